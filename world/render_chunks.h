#pragma once
/// Render chunks of grid bodies, kept in step with brick edits and splits (scene "attachments").
///
///   RenderChunks chunks(8.f);
///   chunks.addHolder(grid, bricks, body, store);      // setup, and each part split off
///   chunks.placed(grid, brick);  chunks.removing(grid, brick);   // as bricks come and go
///   chunks.refresh(grids, store);                      // before the frame's render update
///
/// A grid's render chunk is the union of its bricks' boxes over one cell of `chunk` metres in
/// the grid's frame (a brick belongs to the cell of its box centre). Every body holding the grid
/// carries one primitive attachment per non-empty cell, at the box's centre.
/// Edits cost O(1) a brick: a placed brick merges its box into its cell's (exact); a removed
/// brick leaves the cell's box as it is unless it was the last brick to reach one of the box's
/// six faces (a count per face is kept), and only then is the cell recomputed from the grid's
/// index at the next refresh. A cell left with no brick hides its attachments (empty bounds)
/// and lends them to the next chunk that needs one, so the store grows only to the most chunks
/// ever visible at once.
/// Determinism: edits arrive in the world's serial order; cells are numbered in the order they
/// are first met and refreshed in that order, so the attachments' ids and bounds are a pure
/// function of the scene and its edits (any thread count).
/// At setup, holders added body by body give exactly the layout the render scene always had:
/// per body its chunks in cell order (x, then y, then z).
#include <cstdint>
#include <memory>
#include <span>
#include <unordered_map>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "transforms/attachment_store.h"

namespace bw {

/// What one refresh did (counts; the world reports them).
struct RenderChunkStats {
  uint32_t cellsRefreshed = 0;   ///< cells whose chunks were looked at
  uint32_t cellsRecomputed = 0;  ///< of those, rebuilt from the grid's bricks (a face lost its last brick)
  uint32_t chunksAdded = 0;      ///< primitives given out (to refilled cells and new bodies; reused or new)
  uint32_t chunksHidden = 0;     ///< attachments of emptied cells hidden
};

/// Render chunks of every grid body (see file comment).
class RenderChunks {
 public:
  /// Cells of `chunk` metres (> 0).
  explicit RenderChunks(float chunk);

  /// Gives body, which holds grid `grid` (bricks), one attachment per chunk. The first holder of
  /// a grid also builds its cells. Attachments come from the hidden ones first (none at setup).
  void addHolder(uint32_t grid, const BrickGrid& bricks, uint32_t body, AttachmentStore& store);
  /// A primitive for body from the hidden ones, or a new one (parts' and new bodies' proxies).
  uint32_t acquire(AttachmentStore& store, uint32_t body, const Vec3f& localTranslation, const Aabb& localBounds);

  /// brick was just placed in grid (ignored for grids without holders).
  void placed(uint32_t grid, const Brick& brick);
  /// brick is about to leave grid (removed, moved to a part, or dropped as debris).
  void removing(uint32_t grid, const Brick& brick);
  /// grid changed in ways not reported brick by brick (World::editGrid): every cell is rebuilt.
  void gridChanged(uint32_t grid);
  /// Brings every touched cell's attachments up to date with grids (between steps, serial).
  RenderChunkStats refresh(std::span<const std::unique_ptr<BrickGrid>> grids, AttachmentStore& store);

  /// Cell edge.
  float chunk() const { return chunk_; }
  /// Hidden attachments waiting to be reused.
  uint32_t hiddenCount() const { return uint32_t(free_.size()); }
  /// Primitives acquire() gave out since construction.
  uint64_t acquiredCount() const { return acquired_; }

 private:
  struct CellKey {
    int64_t x, y, z;
    bool operator==(const CellKey&) const = default;
  };
  struct CellKeyHash {
    size_t operator()(const CellKey& k) const;
  };
  // Cell key -> slot, open addressing with the key stored beside its slot: an edited brick's
  // lookup is one probe into one array (a node-based map missed the cache on every edit:
  // 0.3-0.4 us a brick on ship_refit).
  class CellTable {
   public:
    /// The slot of key, or kInvalidIndex.
    uint32_t find(const CellKey& key) const;
    /// Adds key -> slot (key not present).
    void insert(const CellKey& key, uint32_t slot);

   private:
    struct Entry {
      CellKey key;
      uint32_t slot = kInvalidIndex;
    };
    std::vector<Entry> entries_;  // power-of-two size, at most half full
    uint32_t count_ = 0;
  };
  // One cell of one grid: the union of its bricks' boxes and how many bricks reach each face
  // (min x, y, z, then max x, y, z).
  struct Cell {
    CellKey key;
    Aabb box = Aabb::empty();
    uint32_t bricks = 0;
    uint32_t onFace[6] = {};
    bool stale = false;    // a face lost its last brick: rebuild from the grid
    bool touched = false;  // in the grid's touched list
  };
  struct GridCells {
    CellTable slotOf;
    std::vector<Cell> cells;                   // by slot (order first met)
    std::vector<uint32_t> holders;             // bodies holding the grid
    std::vector<std::vector<uint32_t>> ids;    // [holder][slot]: attachment, or kInvalidIndex
    std::vector<uint32_t> touched;             // slots edited since the last refresh
    bool whole = false;                        // gridChanged(): rebuild every cell
    bool dirty = false;                        // in dirtyGrids_
  };

  CellKey keyOf(const Aabb& brickBox) const;
  Aabb cellBox(const CellKey& key) const;
  uint32_t slot(GridCells& g, const CellKey& key);
  void touch(uint32_t grid, uint32_t slot);
  void markDirty(uint32_t grid);
  static void mergeBrick(Cell& cell, const Aabb& box);
  void rebuildCell(const BrickGrid& bricks, Cell& cell, std::vector<uint32_t>& scratch) const;
  void rebuildGrid(const BrickGrid& bricks, uint32_t grid);
  void hideCell(GridCells& g, uint32_t slot, AttachmentStore& store, RenderChunkStats& stats);
  void showCell(GridCells& g, uint32_t slot, AttachmentStore& store);

  float chunk_;
  std::vector<GridCells> grids_;  // by world grid index (holders empty: not rendered)
  std::vector<uint32_t> dirtyGrids_;  // grids touched or changed since the last refresh (a refresh visits only these)
  std::vector<uint32_t> free_;    // hidden attachments, reused last-in first-out
  std::vector<uint32_t> scratch_; // brick ids of a rebuilt cell
  uint64_t acquired_ = 0;
};

}  // namespace bw
