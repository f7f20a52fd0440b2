// The scene's render attachments (scene "attachments"): what a game would hang on its bodies.
// Every primitive body gets one proxy of its shape's bounds; a grid body one proxy per render
// chunk of its bricks (cells of attachments.renderChunk in the grid's frame, render_chunks.h)
// plus its build's lights; a terrain one proxy of its voxel bounds. Grid copies share their
// template's cells and lights. Everything rides directly on its body (depth 0); ids follow body
// order, then chunk order (cells sorted), so the render scene's layout is a pure function of
// the scene. Then, before every render frame, the chunks follow the frame's brick edits (edit
// load, removeBricks, editGrid), and bodies added since (parts split off grids, slabs broken
// off terrains) get theirs, reusing the attachments of emptied chunks first. Lights are
// registered once, at setup: a lamp whose nearest brick goes to a part split off moves to the
// part's body (same offset: the part keeps the grid's coordinates).
#include <algorithm>

#include "collision/bricks/brick_geometry.h"
#include "world/world.h"

namespace bw {

AttachmentStore World::buildAttachments() {
  renderChunks_ = std::make_unique<RenderChunks>(scene_.attachments.renderChunk);
  AttachmentStore store;
  gridLightIds_.assign(grids_.size(), {});
  for (uint32_t body = 0; body < bodies_.size(); ++body) addBodyAttachments(body, store, true);
  renderedBodies_ = bodies_.size();
  return store;
}

void World::addBodyAttachments(uint32_t body, AttachmentStore& store, bool setup) {
  const BodyShape& shape = bodies_.shape[body];
  if (shape.isGrid()) {
    renderChunks_->addHolder(shape.grid, *grids_[shape.grid], body, store);
    // note: only at setup: the render thread registers its lights once. A part's lights are
    // its old grid's, moved over (moveLights).
    const bool first = gridBodies_[shape.grid].front() == body;
    if (setup && scene_.attachments.gridLights)
      for (const BuildLight& light : gridLights_[shape.grid]) {
        const uint32_t id = store.addLight(body, kInvalidIndex, light.position, Quatf::Identity(), light.radius);
        if (first) gridLightIds_[shape.grid].push_back(id);
      }
  } else if (shape.isTerrain()) {
    const Terrain& t = *terrains_[shape.terrain];
    const Int3 size = t.voxels().size();
    const Vec3f extent = Vec3f(float(size.x), float(size.y), float(size.z)) * t.voxelSize();
    renderChunks_->acquire(store, body, extent * 0.5f, Aabb{-extent * 0.5f, extent * 0.5f});
  } else {
    const Vec3f h = shape.primitive.localHalfExtents();
    renderChunks_->acquire(store, body, Vec3f::Zero(), Aabb{-h, h});
  }
}

void World::refreshAttachments() {
  // Edited cells first, so chunks they hid can go to the parts split off this frame.
  AttachmentStore& store = render_->attachments();
  stats_.renderChunks = renderChunks_->refresh(grids_, store);
  const uint64_t acquired = renderChunks_->acquiredCount();
  for (; renderedBodies_ < bodies_.size(); ++renderedBodies_) addBodyAttachments(renderedBodies_, store, false);
  stats_.renderChunks.chunksAdded += uint32_t(renderChunks_->acquiredCount() - acquired);
  for (const auto& [id, grid] : lightMoves_) store.rebindLight(id, gridBodies_[grid].front());
  lightMoves_.clear();
}

std::vector<uint32_t> World::lightsOnPart(uint32_t g, const std::vector<uint32_t>& part) const {
  std::vector<uint32_t> out;
  if (!render_ || g >= gridLightIds_.size() || gridLightIds_[g].empty()) return out;
  // A lamp goes with the brick nearest to it (within kLampReach: a lamp hangs off a wall or
  // sits on a post, never further out); one with no brick that near stays where it is.
  constexpr float kLampReach = 2.f;
  std::vector<uint32_t> onPart(part);
  std::sort(onPart.begin(), onPart.end());
  const BrickGrid& grid = *grids_[g];
  std::vector<uint32_t> near;
  for (uint32_t k = 0; k < gridLights_[g].size(); ++k) {
    const Vec3f p = gridLights_[g][k].position;
    near.clear();
    grid.overlapBricks(Aabb{p - Vec3f::Constant(kLampReach), p + Vec3f::Constant(kLampReach)}, 0xFFFFFFFFu, near);
    uint32_t nearest = kInvalidIndex;
    float best = kLampReach * kLampReach;
    for (uint32_t id : near) {
      const Aabb box = brickBounds(grid.brick(id));
      const float d = (p.cwiseMax(box.min).cwiseMin(box.max) - p).squaredNorm();
      if (d < best || (d == best && id < nearest)) {
        best = d;
        nearest = id;
      }
    }
    if (nearest != kInvalidIndex && std::binary_search(onPart.begin(), onPart.end(), nearest)) out.push_back(k);
  }
  return out;
}

void World::moveLights(uint32_t g, uint32_t ng, const std::vector<uint32_t>& lights) {
  if (lights.empty()) return;
  gridLightIds_.resize(grids_.size());
  std::vector<BuildLight> kept;
  std::vector<uint32_t> keptIds;
  size_t next = 0;
  for (uint32_t k = 0; k < gridLights_[g].size(); ++k) {
    const bool moves = next < lights.size() && lights[next] == k;
    next += moves;
    const uint32_t id = gridLightIds_[g][k];
    if (!moves) {
      kept.push_back(gridLights_[g][k]);
      keptIds.push_back(id);
      continue;
    }
    // The part's grid keeps the old grid's coordinates: the lamp's offset stays as it is.
    gridLights_[ng].push_back(gridLights_[g][k]);
    gridLightIds_[ng].push_back(id);
    lightMoves_.push_back({id, ng});
  }
  gridLights_[g] = std::move(kept);
  gridLightIds_[g] = std::move(keptIds);
}

}  // namespace bw
