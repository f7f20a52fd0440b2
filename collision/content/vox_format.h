#pragma once
/// The .vox file format: the chunk walk under MAIN (PACK, SIZE/XYZI models, the RGBA palette,
/// skipped chunks) and the nTRN/nGRP/nSHP scene graph, read into nodes and walked into one
/// instance per root -> shape path. Kept apart from the palette and material rules
/// (vox_materials.cpp) and from the build step (vox_reader.cpp: bounds and counts of the placed
/// model set, then the terrain) so that the byte-level checks can be read on their own; the
/// layout is documented in vox_reader.h. Internal to the reader: not part of the public API.
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "collision/content/vox_reader.h"

namespace bw::vox {

enum class NodeKind : uint8_t { Transform, Group, Shape };

struct SceneNode {
  NodeKind kind = NodeKind::Transform;
  std::vector<int32_t> children;  // nTRN: one child; nGRP: any; nSHP: none
  Int3 translation;               // nTRN frame 0
  bool rotated = false;           // nTRN frame 0 has a non-identity _r
  int32_t model = -1;             // nSHP: first model
  uint32_t frames = 1;            // nSHP: models listed (animation frames); nTRN: frames listed
};

// Reads the header, the MAIN chunk and its children into `set`: version, models, palette
// (the default one unless an RGBA chunk replaces it), fileVoxels and skippedChunks. Returns the
// scene graph's nodes by id (empty without nTRN/nGRP/nSHP chunks). Nothing is placed yet.
std::map<int32_t, SceneNode> readVoxChunks(const uint8_t* data, size_t size, const std::string& file, VoxModelSet& set);

// Walks the scene graph from node 0, appending one instance per root -> nSHP path.
class SceneWalker {
 public:
  SceneWalker(const std::map<int32_t, SceneNode>& nodes, const std::vector<VoxModel>& models,
              const std::string& file)
      : nodes_(nodes), models_(models), file_(file) {}

  void walk(std::vector<VoxInstance>& out, uint32_t& transformsApplied, uint32_t& ignoredRotations);

 private:
  void visit(int32_t id, Int3 t, bool rotated, int depth, std::vector<VoxInstance>& out, uint32_t& transforms);

  const std::map<int32_t, SceneNode>& nodes_;
  const std::vector<VoxModel>& models_;
  const std::string& file_;
  std::vector<int32_t> path_;
  std::set<int32_t> rotatedNodes_;
};

}  // namespace bw::vox
