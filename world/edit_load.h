#pragma once
/// A scene's edit load (EditLoadDescription): each frame's seeded brick removals, placements,
/// carved holes and wall courses, applied to the world's grids between steps. World::step calls
/// apply() before it simulates the frame; the world then wakes what rests on edited grids,
/// drops their cached contacts and refreshes a dynamic grid's mass (World::applyGridEdits).
///
///   EditLoad load(scene.edits, gridIndexOfEachStream);
///   EditLoadStats s = load.apply(frame, grids, editedGrids);   // editedGrids: grids it touched
///
/// Deterministic: the choices come from each stream's own seeded generator (splitmix64, not a
/// standard distribution, so every standard library picks the same bricks) and the order of
/// the grid's live bricks, which only edits change. A grid edited through World::editGrid
/// outside the load is noticed (its edit count moved) and its brick list taken again.
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "world/scene_description.h"

namespace bw {

struct EditLoadStats {
  uint32_t removed = 0;  ///< bricks removed this frame
  uint32_t placed = 0;   ///< bricks placed this frame
  uint32_t skipped = 0;  ///< placements given up (no free spot found) or removals with no brick left
  /// Time inside the grids' placeBrick / removeBrick (index and mass), apart from the load's
  /// own choosing (random picks, free-spot checks), which a game's edits would not repeat.
  double gridEditMs = 0;
};

/// Bricks a stream places at most over the frames [0, frames): what a grid's pool must hold
/// beyond its own bricks.
uint64_t plannedPlacements(const EditLoadDescription& d, uint64_t frames);

class EditLoad {
 public:
  EditLoad() = default;
  /// streams[i] edits the grid at gridIndex[i].
  EditLoad(std::vector<EditLoadDescription> streams, std::vector<uint32_t> gridIndex);

  bool empty() const { return streams_.empty(); }
  /// Whether a brick with these grid-local bounds would be built into something other than the
  /// grid (a body standing there): such spots count as taken.
  using Blocked = std::function<bool(uint32_t grid, const Aabb& localBounds)>;
  /// Called around each brick edit (connectivity bookkeeping): before a removal, after a placement.
  struct Hooks {
    std::function<void(uint32_t grid, uint32_t brick)> beforeRemove, afterPlace;
  };
  /// Applies frame `frame`'s edits; appends each grid it edited to `edited` (once per stream).
  EditLoadStats apply(uint64_t frame, const std::vector<std::unique_ptr<BrickGrid>>& grids, std::vector<uint32_t>& edited,
                      const Blocked& blocked = {}, const Hooks& hooks = {});
  /// Whether any stream places bricks (the caller then has `blocked` answer).
  bool places() const;
  /// The grid-local bounds of every brick the last apply() placed or removed, with its grid.
  const std::vector<std::pair<uint32_t, Aabb>>& touched() const { return touched_; }

 private:
  // The live bricks of one grid, for picking one at random in O(1) and dropping one in O(1).
  struct LiveBricks {
    std::vector<uint32_t> ids;
    std::vector<uint32_t> slot;   // by brick id: its index in ids
    uint64_t edit = ~0ull;        // the grid's edit count when ids was last right
    void sync(const BrickGrid& grid);
    void add(uint32_t id);
    void drop(uint32_t id);
  };
  struct Stream {
    EditLoadDescription d;
    uint32_t grid;
    uint64_t rng;
    uint64_t wallLaid = 0;   // Wall: bricks laid (or skipped) so far
    float wallBase = 0.f;    // Wall: grid-local z of its first course's bottom, y of its line
    float wallY = 0.f;
    bool wallStarted = false;
  };
  /// The stream's random draws (splitmix64 on its state): a copy of the state draws ahead.
  static uint64_t next(uint64_t& rng);
  static uint32_t below(uint64_t& rng, uint32_t n);
  void remove(Stream& s, BrickGrid& grid, LiveBricks& live, EditLoadStats& st);
  void place(Stream& s, BrickGrid& grid, LiveBricks& live, EditLoadStats& st);
  void carve(Stream& s, BrickGrid& grid, LiveBricks& live, EditLoadStats& st);
  void wall(Stream& s, BrickGrid& grid, LiveBricks& live, EditLoadStats& st);
  bool isFree(uint32_t gridIndex, const BrickGrid& grid, const Brick& b);
  /// Asks for what the next kPlaceLookAhead source draws of a place stream will read (their
  /// bricks, then the index paths of the spots on top of them) without drawing.
  void lookAheadPlacements(const Stream& s, const BrickGrid& grid, const LiveBricks& live);
  static constexpr uint32_t kPlaceSources = 4;  // source bricks a placement tries before it is skipped
  static constexpr uint32_t kPlaceLookAhead = 16;  // source draws whose reads are asked for at once
  // The grid edits themselves, timed into stats.gridEditMs.
  uint32_t timedPlace(uint32_t gridIndex, BrickGrid& grid, const Brick& b, EditLoadStats& st);
  void timedRemove(uint32_t gridIndex, BrickGrid& grid, uint32_t id, EditLoadStats& st);
  /// Places pending_ (its index paths asked for first) and empties it.
  void placePending(uint32_t gridIndex, BrickGrid& grid, LiveBricks& live, EditLoadStats& st);

  std::vector<Stream> streams_;
  std::vector<LiveBricks> live_;   // by grid index (only edited grids fill theirs)
  std::vector<uint32_t> scratch_;  // overlap results
  std::vector<uint32_t> picks_;    // a remove stream's bricks for this frame
  std::vector<Brick> pending_;     // a place stream's group of chosen spots, not placed yet
  std::vector<Brick> aheadSpots_;  // lookAheadPlacements' spots
  const Blocked* blocked_ = nullptr;  // during apply()
  const Hooks* hooks_ = nullptr;      // during apply()
  std::vector<std::pair<uint32_t, Aabb>> touched_;
};

}  // namespace bw
