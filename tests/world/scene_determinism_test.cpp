// Every shipped scene ends in the same state for 1, 2, 4 and 16 threads and from run to run
// (a short run of each: long enough for contacts, islands and sleeping to kick in).
#include <algorithm>
#include <filesystem>
#include <gtest/gtest.h>

#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

uint64_t finalHash(const SceneDescription& scene, int threads, uint32_t frames) {
  World world(scene, threads);
  for (uint32_t f = 0; f < frames; ++f) world.step();
  return world.stateHash();
}

TEST(SceneDeterminism, EveryShippedSceneIsIdenticalForAnyThreadCountAndRun) {
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(BW_SCENES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    SceneDescription scene = loadScene(entry.path().string());
    // note: a tiled build runs the same code whatever its tile count; 2 x 2 keeps the test (and
    // its ASan run) short where lighthouse_tiled's 10 x 10 takes seconds to build five times.
    for (GridDescription& g : scene.grids) {
      g.tilesX = std::min(g.tilesX, 2);
      g.tilesY = std::min(g.tilesY, 2);
    }
    const uint32_t frames = 20;
    const uint64_t reference = finalHash(scene, 1, frames);
    EXPECT_EQ(finalHash(scene, 1, frames), reference) << scene.name << ": run to run";
    for (int threads : {2, 4, 16}) EXPECT_EQ(finalHash(scene, threads, frames), reference) << scene.name << ", " << threads << " threads";
    ++scenes;
  }
  EXPECT_GE(scenes, 6);
}

}  // namespace
}  // namespace bw
