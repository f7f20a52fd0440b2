// AtomicAppendArray under contention (plain std::threads, so ThreadSanitizer sees everything):
// no append lost or duplicated, overflow refused and reported, never written out of bounds.
#include <algorithm>
#include <gtest/gtest.h>
#include <thread>
#include <vector>

#include "render_batch/atomic_append_array.h"

namespace bw {
namespace {

struct Item {
  uint32_t thread;
  uint32_t sequence;
};

/// threads x perThread appends of unique items, all threads released together.
std::vector<uint32_t> appendFromThreads(AtomicAppendArray<Item>& array, uint32_t threads, uint32_t perThread) {
  std::vector<uint32_t> accepted(threads, 0);
  std::atomic<bool> go{false};
  std::vector<std::thread> team;
  for (uint32_t t = 0; t < threads; ++t)
    team.emplace_back([&, t] {
      while (!go.load(std::memory_order_acquire)) std::this_thread::yield();
      for (uint32_t k = 0; k < perThread; ++k) accepted[t] += array.tryAppend({t, k}) ? 1 : 0;
    });
  go.store(true, std::memory_order_release);
  for (auto& th : team) th.join();
  return accepted;
}

TEST(AtomicAppendArray, NoAppendLostOrDuplicatedUnderContention) {
  constexpr uint32_t kThreads = 4, kPerThread = 20'000;
  AtomicAppendArray<Item> array(kThreads * kPerThread);
  for (int round = 0; round < 2; ++round) {  // the second round checks clear()
    array.clear();
    const auto accepted = appendFromThreads(array, kThreads, kPerThread);
    for (uint32_t a : accepted) EXPECT_EQ(a, kPerThread);
    ASSERT_EQ(array.size(), kThreads * kPerThread);
    EXPECT_FALSE(array.overflowed());
    std::vector<uint8_t> seen(kThreads * kPerThread, 0);
    for (uint32_t i = 0; i < array.size(); ++i) {
      const Item it = array[i];
      ASSERT_LT(it.thread, kThreads);
      ASSERT_LT(it.sequence, kPerThread);
      ASSERT_EQ(seen[it.thread * kPerThread + it.sequence]++, 0) << "duplicate " << it.thread << "/" << it.sequence;
    }
  }
}

TEST(AtomicAppendArray, OverflowIsRefusedAndReported) {
  constexpr uint32_t kThreads = 4, kPerThread = 5'000, kCapacity = 7'919;
  // note: the slot vector has exactly kCapacity elements, so under ASan any write past the
  // end would be caught, not silently land in slack capacity.
  AtomicAppendArray<Item> array(kCapacity);
  const auto accepted = appendFromThreads(array, kThreads, kPerThread);
  uint32_t total = 0;
  for (uint32_t a : accepted) total += a;
  EXPECT_EQ(total, kCapacity);
  EXPECT_EQ(array.size(), kCapacity);
  EXPECT_EQ(array.attempted(), uint64_t(kThreads) * kPerThread);
  EXPECT_TRUE(array.overflowed());
  const std::string message = array.overflowMessage("primitive update batch");
  EXPECT_NE(message.find("primitive update batch"), std::string::npos) << message;
  EXPECT_NE(message.find("capacity 7919"), std::string::npos) << message;
  EXPECT_NE(message.find("20000 appended"), std::string::npos) << message;
  // Every stored element is a distinct accepted append.
  std::vector<uint8_t> seen(kThreads * kPerThread, 0);
  for (uint32_t i = 0; i < array.size(); ++i) {
    const Item it = array[i];
    ASSERT_LT(it.thread, kThreads);
    ASSERT_EQ(seen[it.thread * kPerThread + it.sequence]++, 0);
  }
  array.clear();
  EXPECT_FALSE(array.overflowed());
  EXPECT_TRUE(array.tryAppend({0, 0}));
  EXPECT_EQ(array.size(), 1u);
}

TEST(AtomicAppendArray, BlocksFromManyThreadsAreKeptWholeAndOverflowIsCutAtCapacity) {
  // Blocks of up to 64 (what the transform update hands over) from 4 threads: every accepted
  // block lands contiguous; past capacity the block that straddles it keeps only what fits.
  constexpr uint32_t kThreads = 4, kBlocks = 500, kBlock = 37;
  for (const uint32_t capacity : {kThreads * kBlocks * kBlock, 40'000u}) {
    AtomicAppendArray<Item> array(capacity);
    std::vector<std::thread> team;
    std::vector<uint32_t> wholeBlocks(kThreads, 0);
    for (uint32_t t = 0; t < kThreads; ++t)
      team.emplace_back([&, t] {
        Item block[kBlock];
        for (uint32_t b = 0; b < kBlocks; ++b) {
          for (uint32_t k = 0; k < kBlock; ++k) block[k] = {t, b * kBlock + k};
          wholeBlocks[t] += array.tryAppend(block, kBlock) ? 1 : 0;
        }
      });
    for (auto& th : team) th.join();
    EXPECT_EQ(array.attempted(), uint64_t(kThreads) * kBlocks * kBlock);
    EXPECT_EQ(array.size(), std::min<uint32_t>(capacity, kThreads * kBlocks * kBlock));
    EXPECT_EQ(array.overflowed(), capacity < kThreads * kBlocks * kBlock);
    uint32_t accepted = 0;
    for (uint32_t w : wholeBlocks) accepted += w;
    EXPECT_EQ(accepted, capacity / kBlock) << "every block before the one that straddles the capacity fitted";
    // Each stored item is unique, and items of one block sit next to each other in order.
    std::vector<uint8_t> seen(kThreads * kBlocks * kBlock, 0);
    for (uint32_t i = 0; i < array.size(); ++i) {
      const Item& it = array[i];
      ASSERT_EQ(seen[it.thread * kBlocks * kBlock + it.sequence]++, 0);
      if (it.sequence % kBlock != 0 && i > 0) {
        EXPECT_EQ(array[i - 1].thread, it.thread);
        EXPECT_EQ(array[i - 1].sequence + 1, it.sequence);
      }
    }
  }
}

TEST(AtomicAppendArray, ZeroCapacityRefusesEverything) {
  AtomicAppendArray<Item> array(0);
  EXPECT_FALSE(array.tryAppend({1, 2}));
  EXPECT_EQ(array.size(), 0u);
  EXPECT_TRUE(array.overflowed());
}

}  // namespace
}  // namespace bw
