#include "world/islands.h"

#include <algorithm>
#include <bit>

#include "collision/core/ids.h"
#include "world/world_tuning.h"

namespace bw {

uint32_t Islands::find(uint32_t x) {
  while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
  return x;
}

void Islands::build(const std::vector<SolverContact>& contacts, const std::vector<MotionType>& motion) {
  const uint32_t n = uint32_t(motion.size());
  parent_.resize(n);
  for (uint32_t i = 0; i < n; ++i) parent_[i] = i;
  for (const SolverContact& c : contacts) {
    if (motion[c.a] != MotionType::Dynamic || motion[c.b] != MotionType::Dynamic) continue;
    const uint32_t ra = find(c.a), rb = find(c.b);
    if (ra != rb) parent_[std::max(ra, rb)] = std::min(ra, rb);
  }
  // Contacts grouped by the island of their dynamic body, islands ordered by root id (CSR).
  rootIndex_.assign(n, kInvalidIndex);
  roots_.clear();
  auto islandOfContact = [&](const SolverContact& c) { return find(motion[c.a] == MotionType::Dynamic ? c.a : c.b); };
  for (const SolverContact& c : contacts) {
    const uint32_t r = islandOfContact(c);
    if (rootIndex_[r] == kInvalidIndex) {
      rootIndex_[r] = 0;
      roots_.push_back(r);
    }
  }
  std::sort(roots_.begin(), roots_.end());
  for (uint32_t i = 0; i < roots_.size(); ++i) rootIndex_[roots_[i]] = i;
  start_.assign(roots_.size() + 1, 0);
  for (const SolverContact& c : contacts) ++start_[rootIndex_[islandOfContact(c)] + 1];
  for (size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
  contacts_.resize(contacts.size());
  fill_.assign(start_.begin(), start_.end() - 1);
  for (uint32_t k = 0; k < contacts.size(); ++k) contacts_[fill_[rootIndex_[islandOfContact(contacts[k])]]++] = k;
}

void IslandColouring::colour(std::span<const uint32_t> island, const std::vector<SolverContact>& contacts,
                             const std::vector<MotionType>& motion) {
  bodyColours_.resize(motion.size(), 0);
  const uint32_t n = uint32_t(island.size());
  colourOf_.resize(n);
  uint32_t used = 0;
  for (uint32_t j = 0; j < n; ++j) {
    const SolverContact& s = contacts[island[j]];
    uint64_t taken = 0;
    for (uint32_t x : {s.a, s.b})
      if (motion[x] == MotionType::Dynamic) taken |= bodyColours_[x];
    const uint32_t colour = taken == ~uint64_t(0) ? tuning::kMaxColours : uint32_t(std::countr_one(taken));
    if (colour < tuning::kMaxColours)
      for (uint32_t x : {s.a, s.b})
        if (motion[x] == MotionType::Dynamic) bodyColours_[x] |= uint64_t(1) << colour;
    colourOf_[j] = colour;
    used = std::max(used, colour + 1);
  }
  // Counting sort into colour groups, island order kept within a group.
  start_.assign(used + 1, 0);
  for (uint32_t c : colourOf_) ++start_[c + 1];
  for (uint32_t c = 0; c < used; ++c) start_[c + 1] += start_[c];
  contacts_.resize(n);
  fill_.assign(start_.begin(), start_.end() - 1);
  for (uint32_t j = 0; j < n; ++j) contacts_[fill_[colourOf_[j]]++] = island[j];
  for (uint32_t j = 0; j < n; ++j) {
    const SolverContact& s = contacts[island[j]];
    bodyColours_[s.a] = bodyColours_[s.b] = 0;  // clean for the next island
  }
}

}  // namespace bw
