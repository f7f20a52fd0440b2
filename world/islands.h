#pragma once
/// Islands: dynamic bodies joined by contacts, and the colouring that lets one large island be
/// solved on every thread. Static and kinematic bodies do not join islands (the solver reads
/// them, never writes them), so islands touch disjoint dynamic bodies and solve in parallel.
#include <cstdint>
#include <span>
#include <vector>

#include "collision/core/ids.h"
#include "jobs/job_system.h"
#include "jobs/parallel_sort.h"
#include "jobs/profiler.h"
#include "world/body_store.h"
#include "world/solver_contact.h"

namespace bw {

class Islands {
 public:
  /// Finds the islands, then groupContacts() groups the contacts by island (CSR, islands
  /// ordered by their root body). Union-find with
  /// the smaller id as root, run over the contacts in parallel on jobs (zones at stage, stage + 1),
  /// makes the grouping a pure function of the contact list.
  void build(std::span<const SolverContact> contacts, const std::vector<MotionType>& motion, JobSystem& jobs, Profiler& profiler,
             int stage);
  /// Then the contacts of the last build() grouped by island: (root, contact) keys made and
  /// sorted on jobs (zones at stage .. stage + 4), the island ranges read off in one pass
  /// (stage + 5).
  void groupContacts(JobSystem& jobs, Profiler& profiler, int stage);

  uint32_t count() const { return uint32_t(start_.size() - 1); }
  /// Island i's contact count.
  uint32_t size(uint32_t i) const { return start_[i + 1] - start_[i]; }
  /// Indices into the contact list of island i's contacts, in contact order.
  std::span<const uint32_t> contacts(uint32_t i) const {
    return {contacts_.data() + start_[i], contacts_.data() + start_[i + 1]};
  }
  /// The root body of body x's island after build() (x itself for a body without contacts).
  uint32_t root(uint32_t x) const {
    while (parent_[x] != x) x = parent_[x];
    return x;
  }

 private:
  uint32_t find(uint32_t x);
  /// groupContacts() for fewer contacts than the parallel sort takes: serial, in one zone
  /// ("islands: group contacts", stage + 1), the same grouping.
  void groupFewContacts(Profiler& profiler, int stage);
  std::vector<uint32_t> parent_;           // union-find parent per body
  // Each contact's dynamic body, written by build()'s union pass: grouping then reads 4 bytes a
  // contact, not its 192-byte record (monument: the serial grouping of ~250 contacts was 2.2 us
  // a step, mostly those records' cache misses).
  std::vector<uint32_t> contactBody_;
  std::vector<uint32_t> start_{0};         // island i's contacts: contacts_[start_[i], start_[i + 1])
  std::vector<uint32_t> contacts_;
  std::vector<uint64_t> keys_;             // groupContacts(): (root << 32 | contact), sorted
  ParallelSorter<uint64_t> keySorter_;
  // groupFewContacts(): each contact's root, the distinct roots sorted, each root's island
  // (rootSlot_, valid where rootStamp_ is stamp_), the islands' fill positions.
  std::vector<uint32_t> contactRoot_, roots_, rootSlot_, rootStamp_, fill_;
  uint32_t stamp_ = 0;
};

/// One large island's contacts in colours: no two contacts of a colour share a dynamic body,
/// so a colour's contacts can be solved at once on every thread.
class IslandColouring {
 public:
  /// Greedy in island order (the lowest colour free for both bodies), so the colouring is a
  /// pure function of the contact list; a contact for which all kMaxColours are taken goes to a
  /// last, serial group (colour kMaxColours).
  /// Within a colour, contacts go in the order of the cell of the island's bounds holding their
  /// point (`points[k]`, Morton order over 16^3 cells), island order within a cell: a thread's
  /// slice of every colour then lies in one part of the pile, and the bodies there stay in its
  /// cache from colour to colour instead of moving between cores at every wave. Contacts of a
  /// colour share no dynamic body, so their order inside it does not change the result.
  /// On `jobs`: the points' cells in two passes of parallel jobs (zones "colouring: points",
  /// "colouring: cells"), the colours and the cells' order as two jobs side by side (zones
  /// `name` and "colouring: cell order"), then the slots and the order within colours in six
  /// passes of parallel jobs (islands.cpp, placeInSlots), each pass at its profiling stage.
  struct ColouringStages {
    int32_t points, cells, colours, seen, owners, lists, slots, place, cleared;
  };
  void colour(std::span<const uint32_t> island, std::span<const SolverContact> contacts,
              const std::vector<MotionType>& motion, std::span<const SolverContactExtras> points, JobSystem& jobs,
              Profiler& profiler, const char* name, const ColouringStages& stages);

  uint32_t colours() const { return uint32_t(start_.size() - 1); }
  /// Contacts (indices into the contact list) of colour c, in cell order (the serial group,
  /// whose contacts share bodies, in island order).
  std::span<const uint32_t> colour(uint32_t c) const {
    return {solveOrder_.data() + start_[c], solveOrder_.data() + start_[c + 1]};
  }
  /// Every contact of the island, colour by colour, island order within a colour.
  const std::vector<uint32_t>& all() const { return contacts_; }

  /// The island's bodies as the coloured solve keeps them: one slot each, static and kinematic
  /// bodies first (read by every thread, never written) padded to kSlotsApart, then the dynamic
  /// ones in the order the cells first meet them. A thread's slice of a colour then writes
  /// bodies that lie together in memory as well as in space: bodies numbered by the scene
  /// sit scattered, and a thread writing one pulled its neighbours, written by the other
  /// thread, along (crate_pile on two threads: the colour waves' work was 1.65-1.93x one
  /// thread's, 1.26-1.38x in slots; profiles/RESULTS.md, session 32).
  struct SlotPair {
    uint32_t a, b;
  };
  static constexpr uint32_t kSlotsApart = 4;  ///< 32-byte records: a 128-byte line pair
  /// The slots of colour(c)'s contacts' bodies, same positions.
  std::span<const SlotPair> slotPairs(uint32_t c) const {
    return {slotPairs_.data() + start_[c], slotPairs_.data() + start_[c + 1]};
  }
  /// The body in each slot (kInvalidIndex: padding).
  const std::vector<uint32_t>& slotBodies() const { return slotBody_; }

 private:
  /// The greedy colouring (colourOf_, ends_) and the groups in island order (start_, contacts_).
  void colourGroups(std::span<const uint32_t> island, std::span<const SolverContact> contacts,
                    const std::vector<MotionType>& motion);
  /// The Morton cell (16 per axis) of each island contact's point in the points' bounds
  /// (cellOf_), in parallel jobs.
  void cellsOf(std::span<const uint32_t> island, std::span<const SolverContactExtras> points, JobSystem& jobs,
               Profiler& profiler, int32_t pointsStage, int32_t cellsStage);
  /// The island positions in cell order (byCell_).
  void sortByCell();
  std::vector<Aabb> jobBounds_;        // per job of cellsOf's first pass: its points' bounds
  std::vector<uint64_t> bodyColours_;  // per body: colours taken (all zero between calls)
  std::vector<uint32_t> colourOf_, start_, contacts_, fill_;
  std::vector<uint32_t> solveOrder_;   // contacts_ with each colour in cell order
  std::vector<Vec3f> relative_;        // per island position: its point, from the first one's
  std::vector<uint16_t> cellOf_;       // per island position: its cell
  std::vector<uint32_t> cellStart_, byCell_;  // island positions in cell order (counting sort)
  /// Gives the island's bodies (ids below `bodies`) their slots (slotOf_, slotBody_) from ends_
  /// in cell order, and places each colour's contacts in cell order (solveOrder_, slotPairs_).
  void placeInSlots(std::span<const uint32_t> island, uint32_t bodies, JobSystem& jobs, Profiler& profiler,
                    const ColouringStages& stages);
  std::vector<uint32_t> jobCounts_;  // per job of placeInSlots: its counts, then its offsets
  struct Ends {  // an island contact's bodies, read once
    uint32_t a, b;
    bool dynamicA, dynamicB;
  };
  std::vector<Ends> ends_;             // per island position
  std::vector<SlotPair> slotPairs_;    // per solveOrder_ position
  std::vector<uint32_t> slotBody_;
  std::vector<uint32_t> slotOf_;       // per body: its slot (kInvalidIndex between calls)
};

}  // namespace bw
