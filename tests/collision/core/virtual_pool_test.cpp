// VirtualPool: stable addresses, memory returned in any order, slot reuse, clear errors.
#include <algorithm>
#include <gtest/gtest.h>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include "collision/core/argument_checks.h"
#include "collision/core/virtual_pool.h"

namespace bw {
namespace {

// Writes a pattern derived from the index into every byte, so a page that was wrongly given
// back (and so reads as zeros) is caught.
template <size_t N>
struct Patterned {
  uint8_t bytes[N];
  void fill(uint32_t id) {
    for (size_t i = 0; i < N; ++i) bytes[i] = uint8_t((id * 131u + i * 7u) | 1u);
  }
  bool holds(uint32_t id) const {
    for (size_t i = 0; i < N; ++i)
      if (bytes[i] != uint8_t((id * 131u + i * 7u) | 1u)) return false;
    return true;
  }
};

TEST(VirtualPool, AddressesStayStableWhileGrowingTo10M) {
  constexpr uint32_t kCount = 10'000'000;
  VirtualPool<uint64_t> pool(kCount, "stable");
  std::vector<const uint64_t*> sampled;
  for (uint32_t i = 0; i < kCount; ++i) {
    const uint32_t id = pool.allocate(uint64_t(i) * 3 + 1);
    ASSERT_EQ(id, i) << "a fresh pool hands out indices in order";
    if (i % 9973 == 0) sampled.push_back(&pool[id]);
  }
  for (size_t s = 0; s < sampled.size(); ++s) {
    const uint32_t id = uint32_t(s * 9973);
    EXPECT_EQ(sampled[s], &pool[id]);
    EXPECT_EQ(*sampled[s], uint64_t(id) * 3 + 1);
  }
  EXPECT_EQ(pool.size(), kCount);
}

// Distinct pages touched by the given live elements, times the page size.
template <class Pool>
size_t pagesNeededBytes(const Pool& pool, const std::vector<uint32_t>& live, size_t elementSize) {
  const size_t page = VirtualReservation::pageSize();
  std::set<uintptr_t> pages;
  for (uint32_t id : live) {
    const auto addr = reinterpret_cast<uintptr_t>(&pool[id]);
    pages.insert(addr / page);
    pages.insert((addr + elementSize - 1) / page);
  }
  return pages.size() * page;
}

template <size_t N>
void checkResidentAfterRandomFree(uint32_t count, uint64_t seed) {
  VirtualPool<Patterned<N>> pool(count, "resident");
  std::vector<uint32_t> ids(count);
  for (uint32_t i = 0; i < count; ++i) {
    ids[i] = pool.allocate();
    pool[ids[i]].fill(ids[i]);
  }
  const size_t full = pool.residentBytes();
  EXPECT_GE(full, size_t(count) * N) << "the pool must have touched its data";

  std::mt19937_64 rng(seed);
  std::shuffle(ids.begin(), ids.end(), rng);
  const uint32_t keep = count / 100;
  for (uint32_t i = keep; i < count; ++i) pool.free(ids[i]);
  std::vector<uint32_t> live(ids.begin(), ids.begin() + keep);
  for (uint32_t id : live) ASSERT_TRUE(pool[id].holds(id)) << "live data lost at " << id;

  const size_t needed = pagesNeededBytes(pool, live, N);
  const size_t resident = pool.residentBytes();
  EXPECT_LE(resident, 2 * needed) << "element size " << N << ": resident " << resident << " vs pages needed "
                                  << needed << " (full " << full << ")";

  for (uint32_t id : live) pool.free(id);
  EXPECT_TRUE(pool.empty());
  // Only metadata and one spare block may stay resident.
  EXPECT_LT(pool.residentBytes(), full / 20 + 4 * VirtualReservation::pageSize());
}

TEST(VirtualPool, ResidentMemoryAfterFreeing99PercentOf10MInRandomOrder) {
  checkResidentAfterRandomFree<32>(10'000'000, 7);
}

TEST(VirtualPool, ResidentMemoryWithElementsStraddlingPages) {
  // 40 and 24 bytes do not divide a page: blocks straddle page boundaries.
  checkResidentAfterRandomFree<40>(2'000'000, 11);
  checkResidentAfterRandomFree<24>(2'000'000, 12);
  checkResidentAfterRandomFree<5000>(20'000, 13);  // larger than a page
}

TEST(VirtualPool, FreedSlotsAreReused) {
  VirtualPool<uint32_t> pool(100'000, "reuse");
  std::vector<uint32_t> ids;
  for (int i = 0; i < 50'000; ++i) ids.push_back(pool.allocate(uint32_t(i)));
  const uint32_t bound = pool.indexBound();
  std::set<uint32_t> freed;
  for (size_t i = 0; i < ids.size(); i += 3) {
    pool.free(ids[i]);
    freed.insert(ids[i]);
  }
  for (size_t k = 0, n = freed.size(); k < n; ++k) {
    const uint32_t id = pool.allocate(7);
    EXPECT_TRUE(freed.count(id)) << "index " << id << " was not a freed slot";
    freed.erase(id);
  }
  EXPECT_TRUE(freed.empty());
  EXPECT_EQ(pool.indexBound(), bound) << "reuse must not grow the pool";
}

TEST(VirtualPool, ExhaustionIsAClearErrorAndLeavesThePoolIntact) {
  VirtualPool<uint64_t> pool(1000, "tiny pool");
  const uint32_t cap = pool.capacity();
  EXPECT_GE(cap, 1000u);
  for (uint32_t i = 0; i < cap; ++i) pool.allocate(i);
  try {
    pool.allocate(0);
    FAIL() << "allocation past the reservation must throw";
  } catch (const CapacityExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("tiny pool"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("exhausted"), std::string::npos) << e.what();
  }
  EXPECT_EQ(pool.size(), cap);
  for (uint32_t i = 0; i < cap; ++i) ASSERT_EQ(pool[i], i);
  pool.free(5);
  EXPECT_EQ(pool.allocate(99), 5u);
}

TEST(VirtualPool, BadHandlesAndCapacitiesAreRejected) {
  VirtualPool<uint64_t> pool(64, "handles");
  const uint32_t id = pool.allocate(1);
  pool.free(id);
  EXPECT_THROW(pool.free(id), InvalidInput);           // double free
  EXPECT_THROW(pool.free(123456), InvalidInput);       // never allocated
  EXPECT_THROW(pool.free(0xFFFFFFFFu), InvalidInput);  // invalid handle
  EXPECT_THROW(VirtualPool<uint64_t>(0, "zero"), InvalidInput);
  EXPECT_EQ(pool.size(), 0u);
}

struct Counted {
  static inline int alive = 0;
  uint64_t value = 42;
  Counted() { ++alive; }
  ~Counted() { --alive; }
};

TEST(ParallelVirtualPool, ColumnsShareOneIndexSpace) {
  {
    ParallelVirtualPool<uint64_t, float, Counted> pool(10'000, "parallel");
    std::vector<uint32_t> ids;
    for (uint32_t i = 0; i < 5000; ++i) {
      const uint32_t id = pool.allocate();
      pool.get<0>(id) = i;
      pool.get<1>(id) = float(i) * 0.5f;
      ids.push_back(id);
    }
    EXPECT_EQ(Counted::alive, 5000);
    for (uint32_t i = 0; i < 5000; i += 2) pool.free(ids[i]);
    EXPECT_EQ(Counted::alive, 2500);
    for (uint32_t i = 1; i < 5000; i += 2) {
      EXPECT_EQ(pool.get<0>(ids[i]), i);
      EXPECT_EQ(pool.get<1>(ids[i]), float(i) * 0.5f);
      EXPECT_EQ(pool.get<2>(ids[i]).value, 42u);
    }
  }
  EXPECT_EQ(Counted::alive, 0) << "the pool destroys live elements";
}

// Random allocate/free sequences against a std::map model, with element sizes that straddle
// pages and enough churn to release and re-touch blocks many times.
template <size_t N>
void differentialAgainstModel(uint64_t seed, int steps) {
  std::mt19937_64 rng(seed);
  VirtualPool<Patterned<N>> pool(200'000, "model");
  std::map<uint32_t, bool> model;
  std::vector<uint32_t> live;
  for (int step = 0; step < steps; ++step) {
    // Phases of growth and shrinkage so blocks empty out and come back.
    const bool grow = ((step / (steps / 16)) % 2 == 0) ? (rng() % 100 < 70) : (rng() % 100 < 30);
    if (grow || live.empty()) {
      if (pool.size() == pool.capacity()) continue;
      const uint32_t id = pool.allocate();
      ASSERT_FALSE(model.count(id)) << "handed out a live index";
      pool[id].fill(id);
      model[id] = true;
      live.push_back(id);
    } else {
      const size_t k = rng() % live.size();
      const uint32_t id = live[k];
      ASSERT_TRUE(pool[id].holds(id)) << "live element " << id << " corrupted at step " << step;
      pool.free(id);
      model.erase(id);
      live[k] = live.back();
      live.pop_back();
    }
  }
  ASSERT_EQ(pool.size(), model.size());
  std::vector<uint32_t> visited;
  pool.forEachLive([&](uint32_t id) { visited.push_back(id); });
  std::vector<uint32_t> expected;
  for (auto& [id, _] : model) expected.push_back(id);
  EXPECT_EQ(visited, expected) << "forEachLive visits live indices in ascending order";
  for (uint32_t id : live) ASSERT_TRUE(pool[id].holds(id));
}

// Elements with 1-byte alignment and odd sizes: the free-list link must not be a misaligned
// 4-byte access (UBSan checks this in the asan preset).
TEST(VirtualPool, OddSizedUnalignedElementsKeepTheirData) {
  differentialAgainstModel<5>(9, 50'000);
  differentialAgainstModel<1031>(10, 20'000);
}

// freeMany against free() one by one on a twin pool: the same slots handed out afterwards (the
// free lists and released blocks in the same order), the same pages resident, every live
// element's data intact; and the same under DeferPageRelease, whose pages go back at its end.
template <size_t N>
void freeManyEqualsFreeingOneByOne(uint64_t seed, uint32_t count) {
  std::mt19937_64 rng(seed);
  VirtualPool<Patterned<N>> one(count, "one"), many(count, "many"), deferred(count, "deferred");
  std::vector<uint32_t> live;
  for (int round = 0; round < 4; ++round) {
    const uint32_t add = count / 2 - uint32_t(live.size()) / 2;
    for (uint32_t i = 0; i < add && one.size() < count; ++i) {
      const uint32_t a = one.allocate(), b = many.allocate(), c = deferred.allocate();
      ASSERT_EQ(a, b);
      ASSERT_EQ(a, c);
      one[a].fill(a);
      many[a].fill(a);
      deferred[a].fill(a);
      live.push_back(a);
    }
    // A random share (a contiguous run in one round: whole blocks), in a random order.
    std::shuffle(live.begin(), live.end(), rng);
    if (round == 2) std::sort(live.begin(), live.end());
    const size_t k = round == 2 ? live.size() * 3 / 4 : size_t(rng() % live.size());
    const std::vector<uint32_t> gone(live.begin(), live.begin() + long(k));
    live.erase(live.begin(), live.begin() + long(k));
    for (uint32_t h : gone) one.free(h);
    many.freeMany(gone);
    {
      const auto defer = deferred.deferPageRelease();
      for (uint32_t h : gone) deferred.free(h);
    }
    ASSERT_EQ(many.size(), one.size());
    EXPECT_EQ(many.residentBytes(), one.residentBytes()) << "round " << round;
    EXPECT_EQ(deferred.residentBytes(), one.residentBytes()) << "round " << round;
    for (uint32_t h : live) {
      ASSERT_TRUE(many.isLive(h));
      ASSERT_TRUE(many[h].holds(h)) << "live data lost at " << h;
      ASSERT_TRUE(deferred[h].holds(h)) << "live data lost at " << h;
    }
    for (uint32_t h : gone) ASSERT_FALSE(many.isLive(h));
  }
}

TEST(VirtualPool, FreeManyLeavesWhatFreeingOneByOneLeaves) {
  freeManyEqualsFreeingOneByOne<12>(21, 200'000);
  freeManyEqualsFreeingOneByOne<40>(22, 100'000);  // blocks straddle pages
  freeManyEqualsFreeingOneByOne<320>(23, 50'000);
}

// allocateMany against allocate() one by one on a twin pool, through a seeded history of runs
// of every size and frees (one at a time and in bulk) that empties blocks, releases them and
// leaves free lists behind: the same handles in the same order, the same pages resident, and the
// same handles afterwards; a run that does not fit is refused whole.
template <size_t N>
void allocateManyEqualsAllocatingOneByOne(uint64_t seed, uint32_t count) {
  std::mt19937_64 rng(seed);
  VirtualPool<Patterned<N>> one(count, "one"), many(count, "many");
  std::vector<uint32_t> live, run;
  for (int round = 0; round < 60; ++round) {
    const uint32_t free = one.capacity() - one.size();
    const uint32_t n = uint32_t(rng() % 3 == 0 ? rng() % 8 : rng() % std::max<uint32_t>(1, count / 6));
    if (n > free) {
      EXPECT_THROW(many.allocateMany(n, run.data()), CapacityExceeded);
      ASSERT_EQ(many.size(), one.size()) << "a refused run allocates nothing";
      continue;
    }
    run.resize(n);
    many.allocateMany(n, run.data());
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t a = one.allocate();
      ASSERT_EQ(run[k], a) << "run of " << n << " in round " << round << ", slot " << k;
      many[a].fill(a);
      one[a].fill(a);
      live.push_back(a);
    }
    // Free a random share: some one by one, the rest in bulk, so blocks empty, are released and
    // keep free lists.
    std::shuffle(live.begin(), live.end(), rng);
    const size_t gone = live.size() * (rng() % 90) / 100, single = gone / 3;
    for (size_t i = 0; i < single; ++i) {
      one.free(live[i]);
      many.free(live[i]);
    }
    const std::span<const uint32_t> bulk(live.data() + single, gone - single);
    one.freeMany(bulk);
    many.freeMany(bulk);
    live.erase(live.begin(), live.begin() + gone);
    ASSERT_EQ(many.size(), one.size());
    ASSERT_EQ(many.residentBytes(), one.residentBytes()) << "round " << round;
  }
  for (uint32_t h : live) ASSERT_TRUE(many.isLive(h) && many[h].holds(h)) << h;
  for (uint32_t i = 0; i < 1000 && one.size() < one.capacity(); ++i) ASSERT_EQ(many.allocate(), one.allocate());
}

TEST(VirtualPool, AllocateManyHandsOutWhatAllocatingOneByOneDoes) {
  allocateManyEqualsAllocatingOneByOne<12>(31, 60'000);
  allocateManyEqualsAllocatingOneByOne<40>(32, 30'000);  // blocks straddle pages
  allocateManyEqualsAllocatingOneByOne<320>(33, 20'000);
  allocateManyEqualsAllocatingOneByOne<4100>(34, 3'000);  // one slot a block
}

TEST(VirtualPool, FreeManyRefusesADeadOrRepeatedHandleWhole) {
  VirtualPool<Patterned<16>> pool(1000, "pool");
  std::vector<uint32_t> ids;
  for (int i = 0; i < 300; ++i) {
    ids.push_back(pool.allocate());
    pool[ids.back()].fill(ids.back());
  }
  pool.free(ids[7]);
  const auto refused = [&](std::vector<uint32_t> handles, const char* what) {
    try {
      pool.freeMany(handles);
      ADD_FAILURE() << "accepted";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
    EXPECT_EQ(pool.size(), 299u) << "nothing freed";
    for (uint32_t h : handles)
      if (h != ids[7] && h < 1000) {
        EXPECT_TRUE(pool.isLive(h) && pool[h].holds(h));
      }
  };
  refused({ids[1], ids[2], ids[7], ids[3]}, "not a live element");
  refused({ids[1], ids[2], ids[1]}, "listed twice");
  refused({ids[4], 5000}, "not a live element");
  pool.freeMany(std::vector<uint32_t>{ids[1], ids[2]});
  EXPECT_EQ(pool.size(), 297u);
}

TEST(VirtualPool, RandomEditsMatchModel) {
  differentialAgainstModel<12>(1, 300'000);
  differentialAgainstModel<40>(2, 300'000);
  differentialAgainstModel<320>(3, 200'000);
  differentialAgainstModel<4100>(4, 40'000);
}

}  // namespace
}  // namespace bw
