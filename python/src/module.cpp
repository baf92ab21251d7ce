// The _appell extension module: exceptions, then the bindings of each part.
#include "bindings.hpp"

#include <appell/model.hpp>
#include <appell/scene.hpp>

namespace appell::python {

py::str pythonText(const std::string& text) {
  PyObject* decoded = PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "backslashreplace");
  if (!decoded) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(decoded);
}

py::list pythonTexts(const std::vector<std::string>& texts) {
  py::list out;
  for (const std::string& t : texts) out.append(pythonText(t));
  return out;
}

}  // namespace appell::python

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
  // Tried before the two above (pybind11 tries the latest first): their
  // messages may quote bytes that are not UTF-8 (a path, a name), which
  // pybind11's own translation turns into an empty message.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const appell::SceneError& e) {
      const py::object type = py::module_::import("appell._appell").attr("SceneError");
      PyErr_SetObject(type.ptr(), appell::python::pythonText(e.what()).ptr());
    } catch (const appell::ModelError& e) {
      const py::object type = py::module_::import("appell._appell").attr("ModelError");
      PyErr_SetObject(type.ptr(), appell::python::pythonText(e.what()).ptr());
    }
  });
  appell::python::bindScene(m);
  appell::python::bindSimulation(m);
  appell::python::bindAnalysis(m);
  appell::python::bindRun(m);
  appell::python::bindSweep(m);
}
