// The scene's render attachments (scene "attachments"): what a game would hang on its bodies.
// Every primitive body gets one proxy of its shape's bounds; a grid body one proxy per render
// chunk of its bricks (cells of attachments.renderChunk in the grid's frame) plus its build's
// lights; a terrain one proxy of its voxel bounds. Grid copies share their template's chunks
// and lights. Everything rides directly on its body (depth 0); ids follow body order, then
// chunk order (cells sorted), so the render scene's layout is a pure function of the scene.
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "collision/bricks/brick_geometry.h"
#include "world/world.h"

namespace bw {

namespace {

using Cell = std::tuple<int64_t, int64_t, int64_t>;

// A grid's render chunks: the union of brick boxes per cell (a brick goes to the cell of its
// box centre), in cell order.
std::vector<Aabb> renderChunks(const BrickGrid& grid, float chunk) {
  std::map<Cell, Aabb> cells;
  grid.forEachBrick([&](uint32_t id) {
    const Aabb box = brickBounds(grid.brick(id));
    const Vec3f c = box.center();
    const Cell key{int64_t(std::floor(double(c.x()) / chunk)), int64_t(std::floor(double(c.y()) / chunk)),
                   int64_t(std::floor(double(c.z()) / chunk))};
    auto [it, fresh] = cells.try_emplace(key, box);
    if (!fresh) it->second.merge(box);
  });
  std::vector<Aabb> out;
  out.reserve(cells.size());
  for (const auto& [key, box] : cells) out.push_back(box);
  return out;
}

}  // namespace

AttachmentStore World::buildAttachments() const {
  const AttachmentsDescription& desc = scene_.attachments;
  std::vector<std::vector<Aabb>> chunks(grids_.size());
  std::vector<uint8_t> chunked(grids_.size(), 0);
  AttachmentStore store;
  for (uint32_t body = 0; body < bodies_.size(); ++body) {
    const BodyShape& shape = bodies_.shape[body];
    if (shape.isGrid()) {
      if (!chunked[shape.grid]) {
        chunks[shape.grid] = renderChunks(*grids_[shape.grid], desc.renderChunk);
        chunked[shape.grid] = 1;
      }
      for (const Aabb& box : chunks[shape.grid]) {
        const Vec3f c = box.center();
        store.addPrimitive(body, kInvalidIndex, c, Quatf::Identity(), Aabb{box.min - c, box.max - c});
      }
      if (desc.gridLights)
        for (const BuildLight& light : gridLights_[shape.grid])
          store.addLight(body, kInvalidIndex, light.position, Quatf::Identity(), light.radius);
    } else if (shape.isTerrain()) {
      const Terrain& t = *terrains_[shape.terrain];
      const Int3 size = t.voxels().size();
      const Vec3f extent = Vec3f(float(size.x), float(size.y), float(size.z)) * t.voxelSize();
      store.addPrimitive(body, kInvalidIndex, extent * 0.5f, Quatf::Identity(), Aabb{-extent * 0.5f, extent * 0.5f});
    } else {
      const Vec3f h = shape.primitive.localHalfExtents();
      store.addPrimitive(body, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), Aabb{-h, h});
    }
  }
  return store;
}

}  // namespace bw
