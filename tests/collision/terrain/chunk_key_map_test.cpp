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

// Terrains store whole blocks of chunks: the keys of a block (and of most of one, after edits
// freed chunks) must spread over the slots, not queue behind shared home slots. A hash whose
// slot never saw z gave 8-14 probes a lookup on these.
TEST(ChunkKeyMap, TheChunksOfABlockSpreadOverTheSlots) {
  std::mt19937 rng(5);
  const Int3 blocks[] = {{11, 16, 11}, {16, 16, 16}, {32, 8, 32}, {64, 4, 64}, {4, 64, 4}, {1, 1, 200}};
  for (const Int3& dims : blocks) {
    for (const bool thinned : {false, true}) {
      ChunkKeyMap map;
      uint32_t n = 0;
      for (int y = 0; y < dims.y; ++y)
        for (int z = 0; z < dims.z; ++z)
          for (int x = 0; x < dims.x; ++x)
            if (!thinned || rng() % 5 < 3) map.insert(chunkKey({x, y, z}), n++);
      EXPECT_LT(map.meanProbes(), 2.0) << dims.x << " x " << dims.y << " x " << dims.z << (thinned ? ", 60% of it" : "");
      EXPECT_EQ(map.size(), n);
    }
  }
}

}  // namespace
}  // namespace bw
