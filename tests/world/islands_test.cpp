// Islands built by the parallel union-find against a serial reference on random contact lists
// (chains, stars, static and kinematic bodies that must not join islands), for 1, 2, 4 and 16
// threads: the same islands, the same roots (each island's smallest body), the same grouping.
// Labelled `concurrency`: the links are made by compare-and-swap from several threads (TSan).
// And a big island's colouring against a serial reference: its colour groups, the cell order
// inside them and its bodies' slots.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <numeric>

#include "collision/core/seeded_random.h"
#include "world/islands.h"
#include "world/world_tuning.h"

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
  // One Islands per thread count, kept from round to round as a world keeps it from step to
  // step (its scratch sized for other body counts before). Rounds 6-13 are small: fewer
  // contacts than the parallel sort takes, grouped serially (and round 13 has none).
  std::array<Islands, 4> kept;
  for (int round = 0; round < 14; ++round) {
    const bool small = round >= 6;
    const uint32_t bodies = small ? 2 + r.below(700) : 500 + r.below(20'000);
    std::vector<MotionType> motion(bodies, MotionType::Dynamic);
    for (uint32_t i = 0; i < bodies; ++i)
      if (r.below(20) == 0) motion[i] = r.below(2) ? MotionType::Static : MotionType::Kinematic;
    std::vector<SolverContact> contacts;
    // many small islands, or a few huge ones
    const uint32_t count = round == 13 ? 0 : small ? r.below(ParallelSorter<uint64_t>::kSerialBelow) : r.below(3) == 0 ? bodies / 4 : bodies * 2;
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
    for (int t = 0; t < 4; ++t) {
      const int threads = std::array{1, 2, 4, 16}[t];
      SCOPED_TRACE("round " + std::to_string(round) + ", " + std::to_string(threads) + " threads");
      JobSystem jobs(threads);
      Profiler profiler;
      Islands& islands = kept[t];
      islands.build(contacts, motion, jobs, profiler, 0);
      islands.groupContacts(jobs, profiler, 2);
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


// A 16^3 cell's Morton number as IslandColouring documents it: bits interleaved with x highest.
uint32_t referenceCell(const std::array<uint32_t, 3>& q) {
  uint32_t m = 0;
  for (int b = 3; b >= 0; --b)
    for (int a = 0; a < 3; ++a) m = m << 1 | ((q[a] >> b) & 1u);
  return m;
}

// Random piles whose contact points sit at the centres of 16^3 cells of width 0.25 (exact in
// float and double), 10^6 m from the origin, with two contacts at the island's corners so the
// bounds are the cells' own; hubs with more than 64 contacts fill the serial group.
TEST(IslandColouring, GroupsCellOrderAndSlotsMatchASerialReference) {
  SeededRandom r(33);
  constexpr double kWidth = 0.25, kFar = 1.0e6;
  IslandColouring reused;  // coloured again every round: its scratch must come back clean
  for (int round = 0; round < 8; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    const uint32_t bodies = 40 + r.below(3000);
    std::vector<MotionType> motion(bodies, MotionType::Dynamic);
    for (uint32_t i = 1; i < bodies; ++i)
      if (r.below(12) == 0) motion[i] = r.below(2) ? MotionType::Static : MotionType::Kinematic;
    std::vector<uint32_t> dynamic;
    for (uint32_t i = 0; i < bodies; ++i)
      if (motion[i] == MotionType::Dynamic) dynamic.push_back(i);
    const uint32_t count = 600 + r.below(6000);
    std::vector<SolverContact> contacts(count);
    std::vector<SolverContactExtras> extras(count);
    std::vector<uint32_t> cellOf(count);
    const uint32_t hub = dynamic[r.below(uint32_t(dynamic.size()))];
    for (uint32_t k = 0; k < count; ++k) {
      SolverContact& c = contacts[k];
      c.a = r.below(3) == 0 && round % 2 == 0 ? hub : dynamic[r.below(uint32_t(dynamic.size()))];
      c.b = r.below(4) == 0 ? r.below(bodies) : std::min(bodies - 1, c.a + 1 + r.below(8));
      if (c.b == c.a) c.b = (c.a + 1) % bodies;
      std::array<uint32_t, 3> q{r.below(16), r.below(16), r.below(16)};
      double at[3];
      for (int a = 0; a < 3; ++a) at[a] = (q[a] + 0.5) * kWidth;
      if (k < 2) {  // the corners: 0 and 16 cells (the last cell holds its upper face)
        for (int a = 0; a < 3; ++a) at[a] = k == 0 ? 0.0 : 16 * kWidth, q[a] = k == 0 ? 0 : 15;
      }
      extras[k].point = Vec3d(kFar + at[0], -kFar + at[1], kFar + at[2]);
      cellOf[k] = referenceCell(q);
    }
    // The island: a random subset of the contacts, in contact order, with both corners.
    std::vector<uint32_t> island{0, 1};
    for (uint32_t k = 2; k < count; ++k)
      if (r.below(5) != 0) island.push_back(k);

    // Reference: greedy colours in island order, the last group serial.
    std::vector<uint64_t> taken(bodies, 0);
    std::vector<std::vector<uint32_t>> groups(tuning::kMaxColours + 1);
    for (uint32_t k : island) {
      const SolverContact& c = contacts[k];
      uint64_t t = 0;
      for (uint32_t x : {c.a, c.b})
        if (motion[x] == MotionType::Dynamic) t |= taken[x];
      const uint32_t colour = t == ~uint64_t(0) ? tuning::kMaxColours : uint32_t(std::countr_one(t));
      if (colour < tuning::kMaxColours)
        for (uint32_t x : {c.a, c.b})
          if (motion[x] == MotionType::Dynamic) taken[x] |= uint64_t(1) << colour;
      groups[colour].push_back(k);
    }
    while (groups.back().empty()) groups.pop_back();
    if (round % 2 == 0) {
      ASSERT_EQ(groups.size(), tuning::kMaxColours + 1u) << "the hub must fill the serial group";
    }
    // Slots: bodies in the order the contacts in cell order meet them, fixed ones first.
    std::vector<uint32_t> byCell = island;
    std::stable_sort(byCell.begin(), byCell.end(), [&](uint32_t x, uint32_t y) { return cellOf[x] < cellOf[y]; });
    std::vector<uint32_t> fixedOrder, movingOrder;
    std::vector<uint8_t> seen(bodies, 0);
    for (uint32_t k : byCell)
      for (uint32_t x : {contacts[k].a, contacts[k].b}) {
        if (seen[x]) continue;
        seen[x] = 1;
        (motion[x] == MotionType::Dynamic ? movingOrder : fixedOrder).push_back(x);
      }

    for (int threads : {1, 4}) {
      SCOPED_TRACE(std::to_string(threads) + " threads");
      JobSystem jobs(threads);
      Profiler profiler;
      IslandColouring fresh;
      for (IslandColouring* colouring : {&fresh, &reused}) {
        colouring->colour(island, contacts, motion, extras, jobs, profiler, "colouring", {0, 1, 2, 3, 4, 5, 6, 7, 8});
        ASSERT_EQ(colouring->colours(), groups.size());
        // Slots: every island body once, fixed bodies first, the moving ones from a multiple of
        // kSlotsApart, padding only between them.
        const std::vector<uint32_t>& slotBodies = colouring->slotBodies();
        const uint32_t firstMoving =
            uint32_t(fixedOrder.size() + IslandColouring::kSlotsApart - 1) / IslandColouring::kSlotsApart *
            IslandColouring::kSlotsApart;
        ASSERT_EQ(slotBodies.size(), firstMoving + movingOrder.size());
        for (uint32_t i = 0; i < slotBodies.size(); ++i) {
          const uint32_t expected = i < fixedOrder.size()   ? fixedOrder[i]
                                    : i < firstMoving        ? kInvalidIndex
                                                             : movingOrder[i - firstMoving];
          ASSERT_EQ(slotBodies[i], expected) << "slot " << i;
        }
        size_t allAt = 0;
        for (uint32_t c = 0; c < groups.size(); ++c) {
          SCOPED_TRACE("colour " + std::to_string(c));
          const auto group = colouring->colour(c);
          // all(): island order within a colour (the shock sweep's order).
          const std::vector<uint32_t> inIslandOrder(colouring->all().begin() + allAt,
                                                    colouring->all().begin() + allAt + group.size());
          allAt += group.size();
          ASSERT_EQ(inIslandOrder, groups[c]);
          std::vector<uint32_t> expected = groups[c];
          if (c < tuning::kMaxColours)
            std::stable_sort(expected.begin(), expected.end(), [&](uint32_t x, uint32_t y) { return cellOf[x] < cellOf[y]; });
          ASSERT_EQ(std::vector<uint32_t>(group.begin(), group.end()), expected);
          const auto pairs = colouring->slotPairs(c);
          ASSERT_EQ(pairs.size(), group.size());
          for (size_t i = 0; i < group.size(); ++i) {
            ASSERT_EQ(slotBodies[pairs[i].a], contacts[group[i]].a);
            ASSERT_EQ(slotBodies[pairs[i].b], contacts[group[i]].b);
          }
        }
        ASSERT_EQ(allAt, island.size());
      }
    }
  }
}

}  // namespace
}  // namespace bw
