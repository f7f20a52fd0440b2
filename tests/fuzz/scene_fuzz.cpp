// Fuzz target: the scene parser and validation (parseScene), then the world built from what
// passes. Any text either parses or throws SceneError naming the file and field; a scene that
// passes and is small enough to build in a few milliseconds (listed bricks, spawned primitives
// and generated terrains only: no content files, no building generators) builds a World that
// steps three frames with every body's state finite.
#include <cmath>
#include <string>

#include "collision/core/errors.h"
#include "fuzz/fuzz_support.h"
#include "world/scene_budget.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace {

// Limits of the scenes built (the fuzzer finds parser bugs in any scene; worlds it builds must
// stay fast enough to run thousands of times a second).
constexpr uint64_t kMaxBodies = 64, kMaxBricks = 2048, kMaxVoxels = uint64_t(1) << 16;
constexpr uint32_t kMaxRays = 64, kMaxEditsPerFrame = 64;
constexpr int kMaxSubsteps = 4, kMaxIterations = 16, kFrames = 3;

bool smallEnoughToBuild(const bw::SceneDescription& scene) {
  const bw::SceneTotals totals = bw::sceneTotals(scene);
  if (totals.bodies > kMaxBodies || totals.listedBricks > kMaxBricks || totals.generatedVoxels > kMaxVoxels) return false;
  for (const auto& g : scene.grids)
    if (!g.generator.empty() || !g.file.empty()) return false;
  for (const auto& t : scene.terrains)
    if (!t.file.empty()) return false;
  for (const auto& e : scene.edits)
    if (e.perFrame > kMaxEditsPerFrame) return false;
  const bw::SceneSettings& s = scene.settings;
  return scene.rays.count <= kMaxRays && s.substeps <= kMaxSubsteps &&
         s.solverIterations + s.relaxIterations <= kMaxIterations;
}

void stepAndCheck(const bw::SceneDescription& scene) {
  bw::World world(scene, /*threads*/ 1);
  for (int f = 0; f < kFrames; ++f) world.step();
  const bw::BodyStore& b = world.bodies();
  for (size_t i = 0; i < b.position.size(); ++i) {
    FUZZ_CHECK(b.position[i].allFinite() && b.rotation[i].coeffs().allFinite(), "body %zu has a non-finite pose", i);
    FUZZ_CHECK(std::abs(b.rotation[i].norm() - 1.f) < 1e-3f, "body %zu rotation norm %g", i, double(b.rotation[i].norm()));
  }
  (void)world.stateHash();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  bw::SceneDescription scene;
  try {
    // A folder that does not exist: content files named by the input are never found (and
    // never read from wherever the fuzzer runs).
    scene = bw::parseScene(text, "/nonexistent-fuzz-dir/scene.json");
  } catch (const bw::SceneError&) {
    return 0;  // refused with a message naming the field: the documented outcome
  }
  if (!smallEnoughToBuild(scene)) return 0;
  try {
    stepAndCheck(scene);
  } catch (const bw::SceneError&) {
    // the world's own refusals (a body starting inside solid with start_in_solid "refuse", ...)
  } catch (const bw::CapacityExceeded&) {
    // a render batch smaller than the frame (batch_capacity): the step stops naming the batch
  }
  return 0;
}
