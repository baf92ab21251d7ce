// The pieces of the _appell extension module, one file each: scene loading
// and names (scene_bindings.cpp), simulation (simulation_bindings.cpp), whole
// runs and overrides (run_bindings.cpp), a sweep's batches (sweep_bindings.cpp),
// equilibria and linearization (analysis_bindings.cpp), and the helpers they
// share.
#pragma once

#include <appell/output.hpp>
#include <appell/scene.hpp>

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

namespace appell::python {

namespace py = pybind11;

void bindScene(py::module_& m);
void bindSimulation(py::module_& m);
void bindAnalysis(py::module_& m);
void bindRun(py::module_& m);
void bindSweep(py::module_& m);

/// Index of a constraint given by index (negative from the end, as Python
/// does) or by name; IndexError / KeyError otherwise.
int constraintIndex(const Scene& scene, py::handle which);
/// Index of a body given by index or name; IndexError / KeyError otherwise.
int bodyIndex(const Scene& scene, py::handle which);
/// The scene's constant joint forces when it has them (size nv), else empty.
VecX sceneTau(const Scene& scene);

/// Names and messages as Python text: UTF-8, any byte that is not (a link
/// name or a path in another encoding) shown as \xNN instead of making the
/// conversion itself fail (a UnicodeDecodeError from body_names, an empty
/// SceneError message).
py::str pythonText(const std::string& text);
py::list pythonTexts(const std::vector<std::string>& texts);

}  // namespace appell::python
