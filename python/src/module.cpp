// The _appell extension module: exceptions, then the bindings of each part.
#include "bindings.hpp"

#include <appell/model.hpp>
#include <appell/scene.hpp>

PYBIND11_MODULE(_appell, m) {
  namespace py = pybind11;
  m.doc() = "appell: multibody dynamics with exact nonholonomic rolling contacts (C++ core)";
  // C++ exceptions keep their message. std::invalid_argument becomes
  // ValueError, std::out_of_range IndexError, other std::exceptions
  // RuntimeError (pybind11's translation); the engine's own errors get
  // their own classes, derived from RuntimeError as they derive from
  // std::runtime_error.
  py::register_exception<appell::SceneError>(m, "SceneError", PyExc_RuntimeError);
  py::register_exception<appell::ModelError>(m, "ModelError", PyExc_RuntimeError);
  appell::python::bindScene(m);
  appell::python::bindSimulation(m);
  appell::python::bindAnalysis(m);
  appell::python::bindRun(m);
}
