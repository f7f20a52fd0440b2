// Islands built by the parallel union-find against a serial reference on random contact lists
// (chains, stars, static and kinematic bodies that must not join islands), for 1, 2, 4 and 16
// threads: the same islands, the same roots (each island's smallest body), the same grouping.
// Labelled `concurrency`: the links are made by compare-and-swap from several threads (TSan).
#include <gtest/gtest.h>

#include <algorithm>

#include <numeric>

#include "collision/core/seeded_random.h"
#include "world/islands.h"

namespace bw {
namespace {

// Serial union-find: the root of every body (smallest id of its island).
std::vector<uint32_t> referenceRoots(const std::vector<SolverContact>& contacts, const std::vector<MotionType>& motion) {
  std::vector<uint32_t> parent(motion.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x];
    return x;
  };
  for (const SolverContact& c : contacts) {
    if (motion[c.a] != MotionType::Dynamic || motion[c.b] != MotionType::Dynamic) continue;
    const uint32_t ra = find(c.a), rb = find(c.b);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
  }
  std::vector<uint32_t> roots(motion.size());
  for (uint32_t i = 0; i < motion.size(); ++i) roots[i] = find(i);
  return roots;
}

TEST(Islands, ParallelUnionFindEqualsSerialForAnyThreadCount) {
  SeededRandom r(21);
  for (int round = 0; round < 6; ++round) {
    const uint32_t bodies = 500 + r.below(20'000);
    std::vector<MotionType> motion(bodies, MotionType::Dynamic);
    for (uint32_t i = 0; i < bodies; ++i)
      if (r.below(20) == 0) motion[i] = r.below(2) ? MotionType::Static : MotionType::Kinematic;
    std::vector<SolverContact> contacts;
    const uint32_t count = r.below(3) == 0 ? bodies / 4 : bodies * 2;  // many small islands, or a few huge ones
    for (uint32_t k = 0; k < count; ++k) {
      // Only the bodies matter to islands: the other fields stay value-initialised.
      contacts.resize(contacts.size() + 1);
      SolverContact& c = contacts.back();
      c.a = r.below(bodies);
      // Mostly near neighbours (chains and piles), sometimes anywhere (one island spanning all).
      c.b = r.below(4) == 0 ? r.below(bodies) : std::min(bodies - 1, c.a + 1 + r.below(8));
      if (r.below(3) == 0) contacts.push_back(contacts.back());  // pairs with several contacts
    }
    const std::vector<uint32_t> expected = referenceRoots(contacts, motion);
    // The grouping, serially: contacts stably ordered by the root of their dynamic body.
    std::vector<uint32_t> expectedGrouped(contacts.size());
    for (uint32_t k = 0; k < contacts.size(); ++k) expectedGrouped[k] = k;
    auto rootOf = [&](uint32_t k) { return expected[motion[contacts[k].a] == MotionType::Dynamic ? contacts[k].a : contacts[k].b]; };
    std::stable_sort(expectedGrouped.begin(), expectedGrouped.end(), [&](uint32_t x, uint32_t y) { return rootOf(x) < rootOf(y); });
    for (int threads : {1, 2, 4, 16}) {
      SCOPED_TRACE("round " + std::to_string(round) + ", " + std::to_string(threads) + " threads");
      JobSystem jobs(threads);
      Profiler profiler;
      Islands islands;
      islands.build(contacts, motion, jobs, profiler, 0);
      islands.groupContacts(contacts, motion, jobs, profiler, 2);
      for (uint32_t i = 0; i < bodies; ++i) ASSERT_EQ(islands.root(i), expected[i]) << "body " << i;
      std::vector<uint32_t> grouped;
      for (uint32_t is = 0; is < islands.count(); ++is)
        for (uint32_t k : islands.contacts(is)) grouped.push_back(k);
      ASSERT_EQ(grouped, expectedGrouped);
      for (uint32_t is = 0; is < islands.count(); ++is) {  // one island per range, none empty
        ASSERT_FALSE(islands.contacts(is).empty());
        const uint32_t root = rootOf(islands.contacts(is)[0]);
        for (uint32_t k : islands.contacts(is)) ASSERT_EQ(rootOf(k), root);
        if (is > 0) {
          ASSERT_LT(rootOf(islands.contacts(is - 1)[0]), root);
        }
      }
    }
  }
}

}  // namespace
}  // namespace bw
