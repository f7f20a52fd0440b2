#include <gtest/gtest.h>
#include <random>
#include <unordered_map>

#include "collision/terrain/chunk_key_map.h"
#include "collision/terrain/voxel_chunk.h"

namespace bw {
namespace {

TEST(ChunkKeyMap, MatchesUnorderedMapUnderRandomInsertErase) {
  std::mt19937 rng(17);
  ChunkKeyMap map;
  std::unordered_map<uint64_t, uint32_t> ref;
  for (int step = 0; step < 200000; ++step) {
    // A small key range forces collisions, long probe chains and backward shifts.
    const uint64_t key = chunkKey({int(rng() % 40), int(rng() % 4), int(rng() % 40)});
    if (rng() % 3 == 0) {
      EXPECT_EQ(map.erase(key), ref.erase(key) == 1);
    } else {
      const uint32_t v = rng();
      map.insert(key, v);
      ref[key] = v;
    }
    if (step % 997 == 0) {
      ASSERT_EQ(map.size(), ref.size());
      for (int i = 0; i < 50; ++i) {
        const uint64_t k = chunkKey({int(rng() % 40), int(rng() % 4), int(rng() % 40)});
        const auto it = ref.find(k);
        EXPECT_EQ(map.find(k), it == ref.end() ? kInvalidIndex : it->second);
      }
    }
  }
  size_t visited = 0;
  map.forEach([&](uint64_t k, uint32_t v) {
    ++visited;
    ASSERT_EQ(ref.at(k), v);
  });
  EXPECT_EQ(visited, ref.size());
}

TEST(ChunkKeyMap, KeyRoundTripsAndZeroKeyIsValid) {
  const Int3 c{0x1FFFFF, 12345, 0};
  EXPECT_EQ(chunkCoordFromKey(chunkKey(c)), c);
  ChunkKeyMap map;
  EXPECT_EQ(map.find(0), kInvalidIndex);
  map.insert(chunkKey({0, 0, 0}), 7);
  EXPECT_EQ(map.find(0), 7u);
  EXPECT_TRUE(map.erase(0));
  EXPECT_EQ(map.find(0), kInvalidIndex);
}

}  // namespace
}  // namespace bw
