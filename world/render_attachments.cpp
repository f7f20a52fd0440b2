// The scene's render attachments (scene "attachments"): what a game would hang on its bodies.
// Every primitive body gets one proxy of its shape's bounds; a grid body one proxy per render
// chunk of its bricks (cells of attachments.renderChunk in the grid's frame, render_chunks.h)
// plus its build's lights; a terrain one proxy of its voxel bounds. Grid copies share their
// template's cells and lights. Everything rides directly on its body (depth 0); ids follow body
// order, then chunk order (cells sorted), so the render scene's layout is a pure function of
// the scene. Then, before every render frame, the chunks follow the frame's brick edits (edit
// load, removeBricks, editGrid), and bodies added since (parts split off grids, slabs broken
// off terrains) get theirs, reusing the attachments of emptied chunks first. A part's grid has
// no lights of its own: a build's lights stay on the body they were built on.
#include "world/world.h"

namespace bw {

AttachmentStore World::buildAttachments() {
  renderChunks_ = std::make_unique<RenderChunks>(scene_.attachments.renderChunk);
  AttachmentStore store;
  for (uint32_t body = 0; body < bodies_.size(); ++body) addBodyAttachments(body, store);
  renderedBodies_ = bodies_.size();
  return store;
}

void World::addBodyAttachments(uint32_t body, AttachmentStore& store) {
  const BodyShape& shape = bodies_.shape[body];
  if (shape.isGrid()) {
    renderChunks_->addHolder(shape.grid, *grids_[shape.grid], body, store);
    if (scene_.attachments.gridLights)
      for (const BuildLight& light : gridLights_[shape.grid])
        store.addLight(body, kInvalidIndex, light.position, Quatf::Identity(), light.radius);
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
  for (uint32_t body = renderedBodies_; body < bodies_.size(); ++body) addBodyAttachments(body, store);
  stats_.renderChunks.chunksAdded += uint32_t(renderChunks_->acquiredCount() - acquired);
  renderedBodies_ = bodies_.size();
}

}  // namespace bw
