#pragma once
/// Scene files (JSON, schema in profiles/scenes/README.md).
///
/// Every value is validated before anything is built. A bad file throws SceneError whose message
/// names the file, the field path and what was expected, e.g.
///   scenes/x.json: spawners[2].count: expected an integer in 1..1000000, got -5
/// so nothing partially runs.
#include <stdexcept>
#include <string>

#include "world/scene_description.h"

namespace bw {

/// A scene file that cannot be used; the message says where and why.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads and validates a scene file.
SceneDescription loadScene(const std::string& path);
/// Parses and validates scene JSON text; `sourceName` prefixes error messages.
SceneDescription parseScene(const std::string& jsonText, const std::string& sourceName);

}  // namespace bw
