#pragma once
/// Which bricks of a grid hold together: bricks that touch face to face (their bounds meet
/// within a tolerance across an area, not just at an edge or a corner) are connected. Kept as
/// adjacency lists beside the grid, updated per placed or removed brick (one overlap query of
/// the grid's index each), so the question a removal raises, "does the grid fall apart?", walks
/// the lists, never the index.
///
///   BrickConnectivity links(grid);                  // every brick's neighbours, once
///   links.removing(id, seeds);                      // before grid.removeBrick(id): its neighbours
///   grid.removeBrick(id);
///   links.detached(seeds, pieces);                  // the parts no longer joined to the rest
///   uint32_t newId = grid.placeBrick(b);
///   links.placed(grid, newId);
///
/// detached() searches from every seed at once, a few bricks per search in turn (1, 2, 4, ..
/// up to 64 as the rounds go on), and joins two searches when they meet: the common case (the
/// seeds still hang together through bricks near the removed one) ends as soon as all
/// searches have met, after work bounded by the size of the loops around the removal, not by
/// the grid. A search that runs out of bricks before meeting the others has walked a whole
/// piece that fell off; because the searches advance in turn, that piece is found in time
/// proportional to its own size (times the number of searches, plus one turn each), and the
/// piece still growing when all others are done (the big rest) is never walked.
/// Thread safety: const functions may run concurrently; the rest need exclusive access.
#include <cstdint>
#include <span>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "collision/bricks/neighbour_lists.h"

namespace bw {

/// Work done by one detached() call, for the distribution the edit load reports.
struct ConnectivityStats {
  uint32_t visited = 0;  ///< bricks taken off a search's queue
  uint32_t pieces = 0;   ///< parts reported as detached
};

class BrickConnectivity {
 public:
  /// Face contact tolerance (grid units): gaps up to this count as touching, overlaps across
  /// less than this (on a second axis) as an edge or corner contact. Far from the grid origin
  /// it grows to four float steps of the coordinates (toleranceAt).
  static constexpr float kTolerance = 1e-3f;
  static float toleranceAt(const Aabb& box);

  BrickConnectivity() = default;
  /// Every brick's neighbours (one overlap query per brick).
  explicit BrickConnectivity(const BrickGrid& grid);

  /// A part that detached() reported, moved into a grid of its own: its links are taken out of
  /// `from` (a detached part has no neighbour outside itself, so no other list names its
  /// bricks) and renumbered from oldIds[k] to newIds[k] in place: no query of the new grid, no
  /// list allocated. In `from` the part's bricks are gone as if removing() had run for each.
  /// InvalidInput (nothing taken) when the lengths differ, an old id is unknown or a brick has a
  /// neighbour outside the part.
  BrickConnectivity(BrickConnectivity& from, std::span<const uint32_t> oldIds, std::span<const uint32_t> newIds);

  /// Whether two bricks' bounds touch face to face (or overlap).
  static bool touches(const Aabb& a, const Aabb& b);

  /// After grid.placeBrick returned `id`: links it with the bricks it touches.
  void placed(const BrickGrid& grid, uint32_t id);
  /// Before grid.removeBrick(id): unlinks it and appends its neighbours to `seeds`.
  void removing(uint32_t id, std::vector<uint32_t>& seeds);
  /// The parts the seeds (live bricks, typically the neighbours of removed ones) fall into, but
  /// one: appends each part no longer joined to the rest, as its bricks, to `pieces`. The grid
  /// is untouched; the caller moves the pieces out (and calls removing() for their bricks).
  void detached(std::span<const uint32_t> seeds, std::vector<std::vector<uint32_t>>& pieces, ConnectivityStats* stats = nullptr);

  /// The bricks brick `id` touches (empty for an unknown id).
  std::span<const uint32_t> neighbours(uint32_t id) const;

 private:
  void link(uint32_t a, uint32_t b);
  uint32_t find(uint32_t s);

  NeighbourLists adjacency_;   // by brick id
  std::vector<uint8_t> live_;  // by brick id
  std::vector<uint32_t> scratch_;
  // detached(): per brick the search that reached it (valid while stamp == epoch; one record,
  // one cache miss per neighbour looked at), per search its queue and its union-find parent.
  struct Mark {
    uint32_t stamp = 0, owner = 0;
  };
  std::vector<Mark> marks_;
  uint32_t epoch_ = 0;
  std::vector<std::vector<uint32_t>> queues_;
  std::vector<uint32_t> heads_, parent_;
  std::vector<uint8_t> active_, reported_;  // per search root
};

}  // namespace bw
