#include "world/render_chunks.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/argument_checks.h"

namespace bw {

namespace {

// A cell coordinate as an integer: far beyond any grid a scene can hold, clamped so the cast
// stays defined.
int64_t cellCoordinate(float centre, float chunk) {
  const double c = std::floor(double(centre) / double(chunk));
  return int64_t(std::clamp(c, -4e18, 4e18));
}

}  // namespace

size_t RenderChunks::CellKeyHash::operator()(const CellKey& k) const {
  // note: mixed down to the low bits, which the table's mask keeps.
  uint64_t h = uint64_t(k.x) * 0x9E3779B97F4A7C15ull ^ uint64_t(k.y) * 0xC2B2AE3D27D4EB4Full ^ uint64_t(k.z) * 0x165667B19E3779F9ull;
  h ^= h >> 32;
  h *= 0xD6E8FEB86659FD93ull;
  return size_t(h ^ (h >> 32));
}

uint32_t RenderChunks::CellTable::find(const CellKey& key) const {
  if (entries_.empty()) return kInvalidIndex;
  const size_t mask = entries_.size() - 1;
  for (size_t i = CellKeyHash{}(key) & mask;; i = (i + 1) & mask) {
    const Entry& e = entries_[i];
    if (e.slot == kInvalidIndex) return kInvalidIndex;
    if (e.key == key) return e.slot;
  }
}

void RenderChunks::CellTable::insert(const CellKey& key, uint32_t slot) {
  if (2 * (size_t(count_) + 1) > entries_.size()) {
    std::vector<Entry> old(std::max<size_t>(64, entries_.size() * 2));
    old.swap(entries_);
    count_ = 0;
    for (const Entry& e : old)
      if (e.slot != kInvalidIndex) insert(e.key, e.slot);
  }
  const size_t mask = entries_.size() - 1;
  size_t i = CellKeyHash{}(key) & mask;
  while (entries_[i].slot != kInvalidIndex) i = (i + 1) & mask;
  entries_[i] = Entry{key, slot};
  ++count_;
}

RenderChunks::RenderChunks(float chunk) : chunk_(chunk) {
  if (!(chunk > 0) || !std::isfinite(chunk))
    throw InvalidInput("RenderChunks: chunk edge is " + std::to_string(chunk) + ", must be finite and > 0");
}

RenderChunks::CellKey RenderChunks::keyOf(const Aabb& brickBox) const {
  const Vec3f c = brickBox.center();
  return {cellCoordinate(c.x(), chunk_), cellCoordinate(c.y(), chunk_), cellCoordinate(c.z(), chunk_)};
}

Aabb RenderChunks::cellBox(const CellKey& key) const {
  // note: only a query box: any brick whose centre lies in the cell must overlap it, so it is
  // widened past the rounding of the double lattice to float.
  Aabb box;
  const int64_t k[3] = {key.x, key.y, key.z};
  for (int a = 0; a < 3; ++a) {
    const double lo = double(k[a]) * chunk_, hi = double(k[a] + 1) * chunk_;
    const double margin = chunk_ * 1e-3 + std::max(std::abs(lo), std::abs(hi)) * 1e-6;
    box.min[a] = float(lo - margin);
    box.max[a] = float(hi + margin);
  }
  return box;
}

void RenderChunks::mergeBrick(Cell& cell, const Aabb& b) {
  if (cell.bricks++ == 0) {
    cell.box = b;
    std::fill(std::begin(cell.onFace), std::end(cell.onFace), 1u);
    return;
  }
  for (int a = 0; a < 3; ++a) {
    if (b.min[a] < cell.box.min[a]) {
      cell.box.min[a] = b.min[a];
      cell.onFace[a] = 1;
    } else if (b.min[a] == cell.box.min[a]) {
      ++cell.onFace[a];
    }
    if (b.max[a] > cell.box.max[a]) {
      cell.box.max[a] = b.max[a];
      cell.onFace[3 + a] = 1;
    } else if (b.max[a] == cell.box.max[a]) {
      ++cell.onFace[3 + a];
    }
  }
}

uint32_t RenderChunks::slot(GridCells& g, const CellKey& key) {
  const uint32_t found = g.slotOf.find(key);
  if (found != kInvalidIndex) return found;
  const uint32_t s = uint32_t(g.cells.size());
  g.slotOf.insert(key, s);
  g.cells.push_back(Cell{});
  g.cells.back().key = key;
  return s;
}

void RenderChunks::markDirty(uint32_t grid) {
  if (grids_[grid].dirty) return;
  grids_[grid].dirty = true;
  dirtyGrids_.push_back(grid);
}

void RenderChunks::touch(uint32_t grid, uint32_t s) {
  GridCells& g = grids_[grid];
  if (g.cells[s].touched) return;
  g.cells[s].touched = true;
  g.touched.push_back(s);
  markDirty(grid);
}

void RenderChunks::placed(uint32_t grid, const Brick& brick) {
  if (grid >= grids_.size() || grids_[grid].holders.empty()) return;
  GridCells& g = grids_[grid];
  const Aabb box = brickBounds(brick);
  const uint32_t s = slot(g, keyOf(box));
  Cell& cell = g.cells[s];
  if (cell.stale)
    ++cell.bricks;  // rebuilt at the refresh anyway
  else
    mergeBrick(cell, box);
  touch(grid, s);
}

void RenderChunks::removing(uint32_t grid, const Brick& brick) {
  if (grid >= grids_.size() || grids_[grid].holders.empty()) return;
  GridCells& g = grids_[grid];
  const Aabb box = brickBounds(brick);
  const uint32_t s = g.slotOf.find(keyOf(box));
  if (s == kInvalidIndex || g.cells[s].bricks == 0) {
    g.whole = true;  // a brick never reported placed: take the grid again
    markDirty(grid);
    return;
  }
  Cell& cell = g.cells[s];
  touch(grid, s);
  if (--cell.bricks == 0) {
    cell.box = Aabb::empty();
    std::fill(std::begin(cell.onFace), std::end(cell.onFace), 0u);
    cell.stale = false;
    return;
  }
  if (cell.stale) return;
  for (int a = 0; a < 3; ++a) {
    // note: the box keeps its extent while another brick still reaches the face.
    if (box.min[a] == cell.box.min[a] && (cell.onFace[a] == 0 || --cell.onFace[a] == 0)) cell.stale = true;
    if (box.max[a] == cell.box.max[a] && (cell.onFace[3 + a] == 0 || --cell.onFace[3 + a] == 0)) cell.stale = true;
  }
}

void RenderChunks::gridChanged(uint32_t grid) {
  if (grid >= grids_.size() || grids_[grid].holders.empty()) return;
  grids_[grid].whole = true;
  markDirty(grid);
}

void RenderChunks::rebuildCell(const BrickGrid& bricks, Cell& cell, std::vector<uint32_t>& scratch) const {
  Cell fresh;
  fresh.key = cell.key;
  scratch.clear();
  bricks.overlapBricks(cellBox(cell.key), 0xFFFFFFFFu, scratch);
  for (uint32_t id : scratch) {
    const Aabb box = brickBounds(bricks.brick(id));
    if (keyOf(box) == cell.key) mergeBrick(fresh, box);
  }
  if (fresh.bricks != cell.bricks) {
    // Bricks with no filter bits are invisible to the index's queries but still drawn: the
    // count kept brick by brick says some are missing, so the cell is taken from every brick.
    fresh = Cell{};
    fresh.key = cell.key;
    bricks.forEachBrick([&](uint32_t id) {
      const Aabb box = brickBounds(bricks.brick(id));
      if (keyOf(box) == cell.key) mergeBrick(fresh, box);
    });
  }
  cell.box = fresh.box;
  cell.bricks = fresh.bricks;
  std::copy(std::begin(fresh.onFace), std::end(fresh.onFace), std::begin(cell.onFace));
  cell.stale = false;
}

void RenderChunks::rebuildGrid(const BrickGrid& bricks, uint32_t grid) {
  GridCells& g = grids_[grid];
  std::unordered_map<CellKey, Cell, CellKeyHash> fresh;
  bricks.forEachBrick([&](uint32_t id) {
    const Aabb box = brickBounds(bricks.brick(id));
    mergeBrick(fresh[keyOf(box)], box);
  });
  for (uint32_t s = 0; s < g.cells.size(); ++s) {
    Cell& cell = g.cells[s];
    const auto it = fresh.find(cell.key);
    const Cell now = it == fresh.end() ? Cell{} : it->second;
    if (it != fresh.end()) fresh.erase(it);
    cell.box = now.box;
    cell.bricks = now.bricks;
    std::copy(std::begin(now.onFace), std::end(now.onFace), std::begin(cell.onFace));
    cell.stale = false;
    touch(grid, s);
  }
  // Cells met for the first time, in cell order (the layout the render scene always had).
  std::vector<std::pair<CellKey, Cell>> added(fresh.begin(), fresh.end());
  std::sort(added.begin(), added.end(), [](const auto& a, const auto& b) {
    const CellKey &x = a.first, &y = b.first;
    return x.x != y.x ? x.x < y.x : x.y != y.y ? x.y < y.y : x.z < y.z;
  });
  for (auto& [key, cell] : added) {
    cell.key = key;
    cell.touched = false;
    g.slotOf.insert(key, uint32_t(g.cells.size()));
    g.cells.push_back(cell);
    touch(grid, uint32_t(g.cells.size() - 1));
  }
}

uint32_t RenderChunks::acquire(AttachmentStore& store, uint32_t body, const Vec3f& localTranslation, const Aabb& localBounds) {
  ++acquired_;
  if (free_.empty()) return store.addPrimitive(body, kInvalidIndex, localTranslation, Quatf::Identity(), localBounds);
  const uint32_t id = free_.back();
  store.rebindPrimitive(id, body, localTranslation, Quatf::Identity(), localBounds);
  free_.pop_back();
  return id;
}

void RenderChunks::hideCell(GridCells& g, uint32_t s, AttachmentStore& store, RenderChunkStats& stats) {
  for (std::vector<uint32_t>& ids : g.ids) {
    if (ids.size() <= s || ids[s] == kInvalidIndex) continue;
    store.setPrimitiveBounds(ids[s], Aabb::empty());
    free_.push_back(ids[s]);
    ids[s] = kInvalidIndex;
    ++stats.chunksHidden;
  }
}

void RenderChunks::showCell(GridCells& g, uint32_t s, AttachmentStore& store) {
  const Cell& cell = g.cells[s];
  const Vec3f c = cell.box.center();
  const Aabb local{cell.box.min - c, cell.box.max - c};
  for (uint32_t h = 0; h < g.holders.size(); ++h) {
    std::vector<uint32_t>& ids = g.ids[h];
    if (ids.size() <= s) ids.resize(g.cells.size(), kInvalidIndex);
    uint32_t& id = ids[s];
    if (id == kInvalidIndex)
      id = acquire(store, g.holders[h], c, local);
    else if (store.localTranslation(id) != c || !(store.localBounds(id) == local))
      store.rebindPrimitive(id, g.holders[h], c, Quatf::Identity(), local);
  }
}

void RenderChunks::addHolder(uint32_t grid, const BrickGrid& bricks, uint32_t body, AttachmentStore& store) {
  if (grid >= grids_.size()) grids_.resize(size_t(grid) + 1);
  GridCells& g = grids_[grid];
  if (g.holders.empty()) {
    rebuildGrid(bricks, grid);  // the first holder: the grid's cells, in cell order
    for (uint32_t s : g.touched) g.cells[s].touched = false;
    g.touched.clear();
    g.whole = false;
  }
  g.holders.push_back(body);
  g.ids.emplace_back(g.cells.size(), kInvalidIndex);
  std::vector<uint32_t>& ids = g.ids.back();
  for (uint32_t s = 0; s < g.cells.size(); ++s) {
    const Cell& cell = g.cells[s];
    if (cell.bricks == 0) continue;
    const Vec3f c = cell.box.center();
    ids[s] = acquire(store, body, c, Aabb{cell.box.min - c, cell.box.max - c});
  }
}

RenderChunkStats RenderChunks::refresh(std::span<const std::unique_ptr<BrickGrid>> grids, AttachmentStore& store) {
  for (uint32_t gi : dirtyGrids_)  // checked before anything changes
    if (gi >= grids.size())
      throw InvalidInput("RenderChunks::refresh: grid " + std::to_string(gi) + " has render chunks, the world has " +
                         std::to_string(grids.size()) + " grids");
  RenderChunkStats stats;
  const uint64_t acquired = acquired_;
  // note: grids in index order, cells in the order they were first touched, both fixed by the
  // serial edits: hidden attachments are reused in the same order for any thread count.
  std::sort(dirtyGrids_.begin(), dirtyGrids_.end());
  // Two passes: every emptied cell's attachments are hidden (and free) before any cell takes
  // one, so the store grows only when more chunks are visible at once than ever before.
  for (uint32_t gi : dirtyGrids_) {
    GridCells& g = grids_[gi];
    const BrickGrid& bricks = *grids[gi];
    if (g.whole) {
      rebuildGrid(bricks, gi);  // note: the grid is dirty already: dirtyGrids_ does not grow
      g.whole = false;
    }
    for (uint32_t s : g.touched) {
      Cell& cell = g.cells[s];
      if (cell.stale) {
        rebuildCell(bricks, cell, scratch_);
        ++stats.cellsRecomputed;
      }
      if (cell.bricks == 0) hideCell(g, s, store, stats);
    }
  }
  for (uint32_t gi : dirtyGrids_) {
    GridCells& g = grids_[gi];
    for (uint32_t s : g.touched) {
      Cell& cell = g.cells[s];
      if (cell.bricks != 0) showCell(g, s, store);
      cell.touched = false;
      ++stats.cellsRefreshed;
    }
    g.touched.clear();
    g.dirty = false;
  }
  dirtyGrids_.clear();
  stats.chunksAdded = uint32_t(acquired_ - acquired);
  return stats;
}

}  // namespace bw
