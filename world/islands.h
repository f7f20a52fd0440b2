#pragma once
/// Islands: dynamic bodies joined by contacts, and the colouring that lets one large island be
/// solved on every thread. Static and kinematic bodies do not join islands (the solver reads
/// them, never writes them), so islands touch disjoint dynamic bodies and solve in parallel.
#include <cstdint>
#include <span>
#include <vector>

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
  void build(const std::vector<SolverContact>& contacts, const std::vector<MotionType>& motion, JobSystem& jobs, Profiler& profiler,
             int stage);
  /// Then the contacts grouped by island: (root, contact) keys made and sorted on jobs (zones at
  /// stage .. stage + 4), the island ranges read off in one pass (stage + 5).
  void groupContacts(const std::vector<SolverContact>& contacts, const std::vector<MotionType>& motion, JobSystem& jobs,
                     Profiler& profiler, int stage);

  uint32_t count() const { return uint32_t(start_.size() - 1); }
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
  std::vector<uint32_t> parent_;           // union-find parent per body
  std::vector<uint32_t> start_{0};         // island i's contacts: contacts_[start_[i], start_[i + 1])
  std::vector<uint32_t> contacts_;
  std::vector<uint64_t> keys_;             // groupContacts(): (root << 32 | contact), sorted
  ParallelSorter<uint64_t> keySorter_;
};

/// One large island's contacts in colours: no two contacts of a colour share a dynamic body,
/// so a colour's contacts can be solved at once on every thread.
class IslandColouring {
 public:
  /// Greedy in island order (the lowest colour free for both bodies), so the colouring is a
  /// pure function of the contact list; a contact for which all kMaxColours are taken goes to a
  /// last, serial group (colour kMaxColours).
  void colour(std::span<const uint32_t> island, const std::vector<SolverContact>& contacts,
              const std::vector<MotionType>& motion);

  uint32_t colours() const { return uint32_t(start_.size() - 1); }
  /// Contacts (indices into the contact list) of colour c, island order kept within it.
  std::span<const uint32_t> colour(uint32_t c) const {
    return {contacts_.data() + start_[c], contacts_.data() + start_[c + 1]};
  }
  /// Every contact of the island, colour by colour.
  const std::vector<uint32_t>& all() const { return contacts_; }

 private:
  std::vector<uint64_t> bodyColours_;  // per body: colours taken (all zero between calls)
  std::vector<uint32_t> colourOf_, start_, contacts_, fill_;
};

}  // namespace bw
