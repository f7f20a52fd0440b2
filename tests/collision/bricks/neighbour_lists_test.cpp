// NeighbourLists against a vector-of-vectors model under seeded random edits: appends past the
// inline capacity and back, erases anywhere in a list (order kept), clears, and lists moved to
// another set of lists (the part's links), with ids reused after clearing.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "collision/bricks/neighbour_lists.h"

namespace bw {
namespace {

void expectSame(const NeighbourLists& lists, const std::vector<std::vector<uint32_t>>& model, const char* which, int step) {
  ASSERT_GE(lists.size(), model.size());
  for (uint32_t id = 0; id < model.size(); ++id) {
    const std::span<const uint32_t> got = lists[id];
    ASSERT_TRUE(std::equal(got.begin(), got.end(), model[id].begin(), model[id].end()))
        << which << ": list " << id << " differs at step " << step << " (" << got.size() << " vs " << model[id].size() << " ids)";
  }
}

TEST(NeighbourLists, RandomEditsMatchAVectorOfVectors) {
  for (uint64_t seed : {1u, 2u, 3u}) {
    std::mt19937_64 rng(seed);
    constexpr uint32_t kIds = 64;
    NeighbourLists a, b;
    std::vector<std::vector<uint32_t>> ma(kIds), mb(kIds);
    a.grow(kIds);
    b.grow(kIds);
    // Lists around the inline capacity (7) most of the time, now and then a long one.
    for (int step = 0; step < 40'000; ++step) {
      const uint32_t id = uint32_t(rng() % kIds);
      const uint32_t op = uint32_t(rng() % 100);
      const uint32_t cap = id % 8 == 0 ? 40 : 10;
      if (op < 50 && ma[id].size() < cap) {
        const uint32_t v = uint32_t(rng() % 1000);
        a.append(id, v);
        ma[id].push_back(v);
      } else if (op < 92 && !ma[id].empty()) {
        const uint32_t v = ma[id][rng() % ma[id].size()];
        a.erase(id, v);
        ma[id].erase(std::find(ma[id].begin(), ma[id].end(), v));
      } else if (op < 96) {
        a.clear(id);
        ma[id].clear();
      } else {
        // Move the list to b under another id (emptied there first), as a part's links move.
        const uint32_t to = uint32_t(rng() % kIds);
        b.clear(to);
        b.takeFrom(a, id, to);
        mb[to] = std::move(ma[id]);
        ma[id].clear();
      }
      if (step % 997 == 0) {
        expectSame(a, ma, "a", step);
        expectSame(b, mb, "b", step);
      }
    }
    expectSame(a, ma, "a", -1);
    expectSame(b, mb, "b", -1);
    // Renumbering in place through mutableList.
    for (uint32_t id = 0; id < kIds; ++id) {
      for (uint32_t& v : b.mutableList(id)) v += 7;
      for (uint32_t& v : mb[id]) v += 7;
    }
    expectSame(b, mb, "b renumbered", -1);
  }
}

}  // namespace
}  // namespace bw
