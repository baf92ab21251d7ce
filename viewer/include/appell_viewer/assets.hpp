// The viewer page template and its script (three.js + viewer/src bundled),
// embedded in the appell command at build time (viewer/CMakeLists.txt).
#pragma once

#include <string_view>

namespace appell::viewer {

/// page.html: "@TITLE@", "@DATA@" and "@SCRIPT@" mark where the title, the
/// scene-and-motion JSON and the script go.
std::string_view pageTemplate();
/// The bundled script; empty when the build had no node_modules (the
/// command then says how to install them).
std::string_view script();

}  // namespace appell::viewer
