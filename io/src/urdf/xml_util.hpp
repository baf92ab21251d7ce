// Strict reading of XML attributes with messages that name the file, the
// line and the element (TinyXML 1: the one parser of the URDF).
#pragma once

#include <appell/scene.hpp>

#include <tinyxml.h>

#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

namespace appell::io {

/// Where an element came from, for messages. A scene file (a top-level
/// <appell robot="…">) and the description it names are two documents: the
/// description's source also knows the scene file's document, so a message
/// about an element names the file that element is in.
struct XmlSource {
  std::string file;
  const TiXmlDocument* scene_document = nullptr;  ///< the scene file's, when there is one
  std::string scene_file;

  /// The file holding `e` (`file` when `e` is null).
  const std::string& fileOf(const TiXmlElement* e) const;
};

/// "<joint name=\"j1\">" — the tag with its name attribute, if any.
std::string describe(const TiXmlElement* e);

/// "file:line" of an element (its file only when the element is null or has no line).
std::string where(const XmlSource& src, const TiXmlElement* e);
/// "file:line: <element>: reason" — the form of every message (errors and warnings).
std::string located(const XmlSource& src, const TiXmlElement* e, const std::string& reason);
/// Throws SceneError "file:line: <element>: reason".
[[noreturn]] void fail(const XmlSource& src, const TiXmlElement* e, const std::string& reason);
/// Throws SceneError "file: reason".
[[noreturn]] void fail(const XmlSource& src, const std::string& reason);

/// Parses one finite double; nullopt if `text` is not exactly one number
/// (surrounding spaces allowed). `finite` is false for nan/inf.
/// `value` as it goes into a message: at most `keep` characters, then how
/// long it was (an attribute may hold megabytes).
std::string clipped(const std::string& value, std::size_t keep = 64);
/// The end of the start tag at `i`: the first '>' outside quoted values, or
/// npos (the URDF pre-scan and the Collada structure check scan tags so).
std::size_t tagEnd(const std::string& text, std::size_t i);
std::optional<double> parseNumber(const std::string& text, bool* finite = nullptr);

/// Attribute accessors. `what` names the attribute in messages.
bool has(const TiXmlElement* e, const char* attr);
std::string text(const XmlSource& src, const TiXmlElement* e, const char* attr);  ///< required
std::string text(const TiXmlElement* e, const char* attr, const std::string& fallback);
double number(const XmlSource& src, const TiXmlElement* e, const char* attr);      ///< required
double number(const XmlSource& src, const TiXmlElement* e, const char* attr, double fallback);
std::vector<double> numbers(const XmlSource& src, const TiXmlElement* e, const char* attr,
                            int count = -1);  ///< required; count −1: any (≥ 1)
Vec3 vec3(const XmlSource& src, const TiXmlElement* e, const char* attr);
Vec3 vec3(const XmlSource& src, const TiXmlElement* e, const char* attr, const Vec3& fallback);

/// Throws unless every attribute of `e` is one of `allowed` (a misspelt
/// attribute would otherwise be ignored silently).
void allowOnly(const XmlSource& src, const TiXmlElement* e, std::initializer_list<const char*> allowed);

/// `<origin xyz rpy>` child of `e` (identity if absent), as URDF defines it:
/// R = Rz(yaw) Ry(pitch) Rx(roll).
SE3 origin(const XmlSource& src, const TiXmlElement* e);
Mat3 rpyToMatrix(const Vec3& rpy);

}  // namespace appell::io
