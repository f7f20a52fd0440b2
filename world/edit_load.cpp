#include "world/edit_load.h"

#include <algorithm>
#include <chrono>
#include <string>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/argument_checks.h"
#include "collision/core/errors.h"

namespace bw {

uint64_t plannedPlacements(const EditLoadDescription& d, uint64_t frames) {
  if (d.kind != EditLoadDescription::Kind::Place && d.kind != EditLoadDescription::Kind::Wall) return 0;
  if (frames == 0 || d.firstFrame >= frames) return 0;
  const uint64_t last = std::min<uint64_t>(d.lastFrame, frames - 1);
  return uint64_t(d.perFrame) * ((last - d.firstFrame) / d.every + 1);
}

EditLoad::EditLoad(std::vector<EditLoadDescription> streams, std::vector<uint32_t> gridIndex) {
  if (streams.size() != gridIndex.size())
    throw InvalidInput("EditLoad: " + std::to_string(streams.size()) + " streams but " + std::to_string(gridIndex.size()) + " grid indices");
  for (size_t i = 0; i < streams.size(); ++i) {
    Stream s;
    s.d = std::move(streams[i]);
    s.grid = gridIndex[i];
    s.rng = s.d.seed * 0x9E3779B97F4A7C15ull + i;
    streams_.push_back(std::move(s));
    live_.resize(std::max<size_t>(live_.size(), gridIndex[i] + 1));
  }
}

void EditLoad::LiveBricks::sync(const BrickGrid& grid) {
  if (edit == grid.editCount()) return;
  ids.clear();
  grid.forEachBrick([&](uint32_t id) { ids.push_back(id); });
  slot.assign(ids.empty() ? 0 : ids.back() + 1, ~0u);
  for (uint32_t i = 0; i < ids.size(); ++i) slot[ids[i]] = i;
  edit = grid.editCount();
}

void EditLoad::LiveBricks::add(uint32_t id) {
  if (id >= slot.size()) slot.resize(size_t(id) + 1, ~0u);
  slot[id] = uint32_t(ids.size());
  ids.push_back(id);
}

void EditLoad::LiveBricks::drop(uint32_t id) {
  const uint32_t i = slot[id];
  ids[i] = ids.back();
  slot[ids[i]] = i;
  ids.pop_back();
  slot[id] = ~0u;
}

uint32_t EditLoad::timedPlace(uint32_t gridIndex, BrickGrid& grid, const Brick& b, EditLoadStats& st) {
  touched_.push_back({gridIndex, brickBounds(b)});
  const auto t = std::chrono::steady_clock::now();
  const uint32_t id = grid.placeBrick(b);
  st.gridEditMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  ++st.placed;
  if (hooks_ && hooks_->afterPlace) hooks_->afterPlace(gridIndex, id);
  return id;
}

void EditLoad::timedRemove(uint32_t gridIndex, BrickGrid& grid, uint32_t id, EditLoadStats& st) {
  touched_.push_back({gridIndex, brickBounds(grid.brick(id))});
  if (hooks_ && hooks_->beforeRemove) hooks_->beforeRemove(gridIndex, id);
  const auto t = std::chrono::steady_clock::now();
  grid.removeBrick(id);
  st.gridEditMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  ++st.removed;
}

uint64_t EditLoad::next(uint64_t& rng) {  // splitmix64
  uint64_t z = (rng += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

uint32_t EditLoad::below(uint64_t& rng, uint32_t n) { return uint32_t(((next(rng) >> 32) * uint64_t(n)) >> 32); }

bool EditLoad::isFree(uint32_t gridIndex, const BrickGrid& grid, const Brick& b) {
  // Shrunk a little: a brick may touch its neighbours face to face, not overlap them.
  const Aabb box = brickBounds(b);
  const Vec3f inset = box.halfExtent() * 0.02f;
  const Aabb shrunk{box.min + inset, box.max - inset};
  for (const Brick& p : pending_)  // chosen in this group, not placed yet
    if (shrunk.overlaps(brickBounds(p))) return false;
  scratch_.clear();
  grid.overlapBricks(shrunk, ~0u, scratch_);
  return scratch_.empty() && !(blocked_ && *blocked_ && (*blocked_)(gridIndex, box));
}

bool EditLoad::places() const {
  return std::any_of(streams_.begin(), streams_.end(), [](const Stream& s) {
    return s.d.kind == EditLoadDescription::Kind::Place || s.d.kind == EditLoadDescription::Kind::Wall;
  });
}

// note: the frame's picks are drawn first, each dropped from the live list as it is drawn, so
// they are the ones drawing between removals gave (only the load's own drops change the
// list). Known ahead, each group's removals are asked for together: a lone removal in a 1M
// grid waits on a chain of ~12 misses down the index, and a frame of the simulation between
// edits leaves none of it in cache.
void EditLoad::remove(Stream& s, BrickGrid& grid, LiveBricks& live, EditLoadStats& st) {
  picks_.clear();
  for (uint32_t k = 0; k < s.d.perFrame; ++k) {
    if (live.ids.empty()) {
      st.skipped += s.d.perFrame - k;
      break;
    }
    const uint32_t id = live.ids[below(s.rng, uint32_t(live.ids.size()))];
    live.drop(id);
    picks_.push_back(id);
  }
  try {
    for (size_t i = 0; i < picks_.size(); ++i) {
      if (i % BrickGrid::kPrefetchGroup == 0) {
        const auto t = std::chrono::steady_clock::now();
        grid.prefetchRemovals(std::span(picks_).subspan(i, std::min(BrickGrid::kPrefetchGroup, picks_.size() - i)));
        st.gridEditMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
      }
      timedRemove(s.grid, grid, picks_[i], st);
    }
  } catch (...) {
    live.edit = ~0ull;  // picks dropped but not removed: the list is taken again next time
    throw;
  }
}

// note: spots are chosen a group at a time and the group placed together, its index paths
// asked for first: a new brick goes where nothing is yet, so the overlap query that found the
// spot stopped above the nodes the insert walks through, and a lone insert waits on their
// misses one after another. A spot is free of the grid and of the group's earlier choices;
// sources are the grid's live bricks (a group's bricks join them once placed).
//
// A spot is found by an overlap query, a lone walk down the index from the root, and a frame of
// simulation between edit loads leaves little of a 1M-brick ship's index in cache: choosing 500
// spots took 1.8 ms of ship_refit's frame. Which bricks the next draws pick is known before they
// are drawn (a copy of the stream draws them), and 83% of spots are taken on top of the first
// source tried (ship_refit), so the reads of the next draws are asked for together.
void EditLoad::place(Stream& s, BrickGrid& grid, LiveBricks& live, EditLoadStats& st) {
  pending_.clear();
  uint32_t drawn = 0, askedFor = 0;  // source draws made, and those whose reads were asked for
  for (uint32_t k = 0; k < s.d.perFrame; ++k) {
    bool done = false;
    // A few source bricks, each tried on top first, then beside it, where nothing is yet.
    for (uint32_t source = 0; source < kPlaceSources && !done && !live.ids.empty(); ++source) {
      if (drawn == askedFor) {
        lookAheadPlacements(s, grid, live);
        askedFor = drawn + kPlaceLookAhead;
      }
      ++drawn;
      const Brick from = grid.brick(live.ids[below(s.rng, uint32_t(live.ids.size()))]);
      const Vec3f size = brickBounds(from).extent();
      const Vec3f offsets[5] = {{0, 0, size.z()}, {size.x(), 0, 0}, {-size.x(), 0, 0}, {0, size.y(), 0}, {0, -size.y(), 0}};
      for (uint32_t t = 0; t < 5 && !done; ++t) {
        Brick b = from;
        b.position += offsets[t];
        if (!isFree(s.grid, grid, b)) continue;
        pending_.push_back(b);
        done = true;
      }
    }
    st.skipped += done ? 0 : 1;
    if (pending_.size() == BrickGrid::kPrefetchGroup) {
      placePending(s.grid, grid, live, st);
      askedFor = drawn;  // the live list grew: draws from here pick from a longer list
    }
  }
  placePending(s.grid, grid, live, st);
}

void EditLoad::lookAheadPlacements(const Stream& s, const BrickGrid& grid, const LiveBricks& live) {
  if (live.ids.empty()) return;
  uint64_t rng = s.rng;  // the stream's next draws, not drawn
  uint32_t ids[kPlaceLookAhead];
  for (uint32_t i = 0; i < kPlaceLookAhead; ++i) {
    ids[i] = live.ids[below(rng, uint32_t(live.ids.size()))];
    __builtin_prefetch(&grid.brick(ids[i]));
  }
  aheadSpots_.clear();
  for (uint32_t id : ids) {
    Brick top = grid.brick(id);
    top.position.z() += brickBounds(top).extent().z();
    aheadSpots_.push_back(top);
  }
  grid.prefetchPlacements(aheadSpots_);
}

void EditLoad::placePending(uint32_t gridIndex, BrickGrid& grid, LiveBricks& live, EditLoadStats& st) {
  const auto t = std::chrono::steady_clock::now();
  grid.prefetchPlacements(pending_);
  st.gridEditMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  for (const Brick& b : pending_) live.add(timedPlace(gridIndex, grid, b, st));
  pending_.clear();
}

void EditLoad::carve(Stream& s, BrickGrid& grid, LiveBricks& live, EditLoadStats& st) {
  const float r = s.d.radius;
  for (uint32_t k = 0; k < s.d.perFrame && !live.ids.empty(); ++k) {
    const Vec3f centre = grid.brick(live.ids[below(s.rng, uint32_t(live.ids.size()))]).position;
    scratch_.clear();
    grid.overlapBricks(Aabb{centre - Vec3f::Constant(r), centre + Vec3f::Constant(r)}, ~0u, scratch_);
    // note: overlapBricks' order is the index's; sort so the removal order is the ids'.
    std::sort(scratch_.begin(), scratch_.end());
    for (uint32_t id : scratch_) {
      if ((grid.brick(id).position - centre).squaredNorm() > r * r) continue;
      timedRemove(s.grid, grid, id, st);
      live.drop(id);
    }
  }
}

void EditLoad::wall(Stream& s, BrickGrid& grid, LiveBricks& live, EditLoadStats& st) {
  const Vec3f h = s.d.brickHalfSize;
  if (grid.brickCount() == 0) {
    // Nothing to stand on (its bricks were all removed): the wall waits. note: its empty bounds
    // gave a NaN brick (the scene fuzz target).
    st.skipped += s.d.perFrame;
    return;
  }
  if (!s.wallStarted) {
    // On top of the grid, along x, at a seeded y inside its bounds.
    const Aabb b = grid.bounds();
    s.wallBase = b.max.z();
    s.wallY = b.min.y() + (b.max.y() - b.min.y()) * float(below(s.rng, 1000)) / 1000.f;
    s.wallStarted = true;
  }
  const Aabb b = grid.bounds();
  const float x0 = b.min.x() + h.x();
  for (uint32_t k = 0; k < s.d.perFrame; ++k, ++s.wallLaid) {
    const uint64_t course = s.wallLaid / s.d.wallLength, column = s.wallLaid % s.d.wallLength;
    // note: courses alternate by half a brick, as masons lay them.
    const float shift = (course & 1) ? h.x() : 0.f;
    const Brick brick = Brick::box(Vec3f(x0 + shift + 2.f * h.x() * float(column), s.wallY, s.wallBase + h.z() + 2.f * h.z() * float(course)), h);
    if (!isFree(s.grid, grid, brick)) {
      ++st.skipped;
      continue;
    }
    live.add(timedPlace(s.grid, grid, brick, st));
  }
}

EditLoadStats EditLoad::apply(uint64_t frame, const std::vector<std::unique_ptr<BrickGrid>>& grids, std::vector<uint32_t>& edited,
                              const Blocked& blocked, const Hooks& hooks) {
  EditLoadStats st;
  touched_.clear();
  pending_.clear();
  blocked_ = &blocked;
  hooks_ = &hooks;
  struct Reset {
    EditLoad& load;
    ~Reset() {
      load.blocked_ = nullptr;
      load.hooks_ = nullptr;
    }
  } reset{*this};
  for (Stream& s : streams_) {
    if (frame < s.d.firstFrame || frame > s.d.lastFrame || (frame - s.d.firstFrame) % s.d.every != 0) continue;
    BrickGrid& grid = *grids[s.grid];
    LiveBricks& live = live_[s.grid];
    live.sync(grid);
    edited.push_back(s.grid);
    try {
      switch (s.d.kind) {
        case EditLoadDescription::Kind::Remove: remove(s, grid, live, st); break;
        case EditLoadDescription::Kind::Place: place(s, grid, live, st); break;
        case EditLoadDescription::Kind::Carve: carve(s, grid, live, st); break;
        case EditLoadDescription::Kind::Wall: wall(s, grid, live, st); break;
      }
    } catch (const CapacityExceeded& e) {
      // The bricks placed before the full pool stay (each edit is whole); the grid is consistent.
      live.edit = grid.editCount();
      throw CapacityExceeded("edit load on grid '" + s.d.grid + "' at frame " + std::to_string(frame) + ": " + e.what());
    }
    live.edit = grid.editCount();
  }
  return st;
}

}  // namespace bw
