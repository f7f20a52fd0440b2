// Batching regression tests at the world level (issue 16): the world drives the transform
// update and the render batch. After N frames the render scene must equal the world's poses
// composed with the attachment offsets, bit for bit, in every submission mode and for any
// thread count; sleeping bodies submit nothing; a batch overflow is reported, leaves the
// previous frame's render scene, and changes nothing in the physics.
// Labelled `concurrency`: the render thread runs beside the world's workers (TSan in CI).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/errors.h"
#include "transforms/attachment_math.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

// A small scene with every kind of body: a static house with its lamps, a kinematic truck
// driving in a circle with its lights, boxes and spheres raining on the house, and dynamic
// copies of a small brick grid.
SceneDescription renderScene(uint32_t boxes = 60) {
  const std::string json = R"({
    "name": "render_regression",
    "settings": {"frames": 40},
    "grids": [
      {"name": "house", "generator": "house", "scale": 0.25, "seed": 3},
      {"name": "truck", "generator": "truck", "scale": 0.25, "seed": 5, "position": [30, 0, 0],
       "motion": "kinematic", "linear_velocity": [0, 4, 0], "angular_velocity": [0, 0, 0.5]},
      {"name": "crate", "bricks": [
        {"position": [0, 0, 0], "half_size": [0.4, 0.4, 0.24]},
        {"position": [0.8, 0, 0], "half_size": [0.4, 0.4, 0.24]},
        {"position": [0, 0, 0.48], "half_size": [0.4, 0.4, 0.24], "shape": "wedge"}],
       "position": [0, 0, 60], "motion": "dynamic"}
    ],
    "spawners": [
      {"shape": "box", "count": )" + std::to_string(boxes) + R"(, "half_extents": [0.3, 0.3, 0.3],
       "region": {"min": [-4, -4, 8], "max": [4, 4, 20]}, "seed": 2},
      {"shape": "sphere", "count": 20, "radius": 0.25, "region": {"min": [-4, -4, 8], "max": [4, 4, 20]}, "seed": 3},
      {"shape": "grid", "grid": "crate", "count": 4, "region": {"min": [-3, -3, 22], "max": [3, 3, 30]}, "seed": 4}
    ],
    "attachments": {"render_chunk": 2}
  })";
  return parseScene(json, "render_regression.json");
}

// The render scene must hold, for every attachment, its body's shape pose composed with the
// attachment's offset: exactly what a serial reference computes from the world's poses.
void expectSceneMatchesWorld(World& world) {
  const RenderScene& scene = world.renderScene();
  const AttachmentStore& store = world.render()->store();
  const BodyStore& bodies = world.bodies();
  for (uint32_t id = 0; id < store.size(); ++id) {
    const RigidTransform body = bodies.shapePose(store.body(id));
    Vec3d t;
    Quatf r;
    composeAttachmentPose(body.translation, body.rotation, store.localTranslation(id), store.localRotation(id), t, r);
    const WorldMatrix m = makeWorldMatrix(t, r);
    const uint32_t rid = store.renderId(id);
    if (store.kind(id) == AttachmentKind::Primitive) {
      ASSERT_EQ(std::memcmp(&scene.localToWorldTranslation(rid), &m.translation, sizeof(Vec3d)), 0) << "proxy " << rid;
      ASSERT_EQ(std::memcmp(&scene.localToWorldLinear(rid), &m.linear, sizeof(Mat3f)), 0) << "proxy " << rid;
      const WorldBounds b = makeWorldBounds(store.localBounds(id), m);
      ASSERT_EQ(std::memcmp(&scene.boundsOrigin(rid), &b.origin, sizeof(Vec3d)), 0) << "proxy " << rid;
      ASSERT_EQ(std::memcmp(&scene.boundsExtent(rid), &b.extent, sizeof(Vec3f)), 0) << "proxy " << rid;
    } else {
      ASSERT_EQ(std::memcmp(&scene.lightPosition(rid), &t, sizeof(Vec3d)), 0) << "light " << rid;
    }
  }
}

TEST(WorldRender, EveryBodyGetsProxiesGridsGetChunksAndLights) {
  const SceneDescription desc = renderScene();
  World world(desc, 1);
  ASSERT_NE(world.render(), nullptr);
  const AttachmentStore& store = world.render()->store();
  std::vector<uint32_t> perBody(world.bodies().size(), 0), lightsPerBody(world.bodies().size(), 0);
  for (uint32_t id = 0; id < store.size(); ++id) {
    ++perBody[store.body(id)];
    if (store.kind(id) == AttachmentKind::Light) ++lightsPerBody[store.body(id)];
  }
  for (uint32_t b = 0; b < world.bodies().size(); ++b) {
    EXPECT_GE(perBody[b], 1u) << "body " << b << " has no render proxy";
    if (!world.bodies().shape[b].isGrid()) {
      EXPECT_EQ(perBody[b], 1u) << "a primitive body has one proxy";
    }
  }
  // The house is 2 m chunked: many proxies, each inside the grid's bounds, and its lamps.
  EXPECT_GT(perBody[0] - lightsPerBody[0], 10u);
  EXPECT_GT(lightsPerBody[0], 0u) << "the house generator's lamps";
  EXPECT_GT(lightsPerBody[1], 0u) << "the truck's head and tail lights";
  const Aabb houseBounds = world.grid(0).bounds();
  float largestBrick = 0;
  world.grid(0).forEachBrick([&](uint32_t id) { largestBrick = std::max(largestBrick, brickBounds(world.grid(0).brick(id)).extent().maxCoeff()); });
  for (uint32_t id = 0; id < store.size(); ++id) {
    if (store.body(id) != 0 || store.kind(id) != AttachmentKind::Primitive) continue;
    const Aabb box{store.localBounds(id).min + store.localTranslation(id), store.localBounds(id).max + store.localTranslation(id)};
    EXPECT_TRUE((box.min.array() >= houseBounds.min.array() - 1e-4f).all() && (box.max.array() <= houseBounds.max.array() + 1e-4f).all());
    EXPECT_LE(box.extent().maxCoeff(), 2.f + largestBrick + 1e-4f) << "a chunk holds bricks whose centres share one 2 m cell";
  }
  // Copies of the crate grid share its chunks: the same number of proxies per copy.
  const uint32_t crateTemplate = 2;
  for (uint32_t b = 3; b < world.bodies().size(); ++b)
    if (world.bodies().shape[b].isGrid()) {
      EXPECT_EQ(perBody[b], perBody[crateTemplate]);
    }
}

TEST(WorldRender, RenderSceneEqualsWorldPosesInEveryModeAndThreadCount) {
  const SceneDescription desc = renderScene();
  constexpr uint32_t kFrames = 40;
  uint64_t referenceScene = 0, referenceState = 0;
  for (SubmissionMode mode : {SubmissionMode::Batched, SubmissionMode::PerObjectMutexNoRadius, SubmissionMode::PerObjectConcurrentNoRadius,
                              SubmissionMode::PerObjectMutex}) {
    for (int threads : {1, 2, 4, 16}) {
      SCOPED_TRACE(std::string(submissionModeName(mode)) + ", " + std::to_string(threads) + " threads");
      World world(desc, threads, mode);
      uint64_t records = 0;
      for (uint32_t f = 0; f < kFrames; ++f) {
        world.step();
        records += world.lastStats().render.primitives + world.lastStats().render.lights;
      }
      EXPECT_GT(records, world.render()->store().size()) << "bodies kept moving after the first frame";
      expectSceneMatchesWorld(world);
      const uint64_t sceneHash = world.renderScene().stateHash();
      if (referenceScene == 0) {
        referenceScene = sceneHash;
        referenceState = world.stateHash();
      }
      EXPECT_EQ(sceneHash, referenceScene) << "render scene differs from batched, 1 thread";
      EXPECT_EQ(world.stateHash(), referenceState);
    }
  }
}

TEST(WorldRender, ShippedSceneRenderSceneEqualsWorldPosesInEveryModeAndThreadCount) {
  // truck_in_station: a kinematic ring station with its lights spinning, a dynamic truck with
  // head and tail lights driving on its floor, crates in its bed; every kind of moving proxy.
  SceneDescription desc = loadScene(std::string(BW_SCENES_DIR) + "/truck_in_station.json");
  ASSERT_TRUE(desc.attachments.enabled);
  constexpr uint32_t kFrames = 30;
  uint64_t referenceScene = 0;
  for (SubmissionMode mode : {SubmissionMode::Batched, SubmissionMode::PerObjectMutexNoRadius, SubmissionMode::PerObjectConcurrentNoRadius}) {
    for (int threads : {1, 2, 4, 16}) {
      SCOPED_TRACE(std::string(submissionModeName(mode)) + ", " + std::to_string(threads) + " threads");
      World world(desc, threads, mode);
      for (uint32_t f = 0; f < kFrames; ++f) world.step();
      EXPECT_GT(world.lastStats().render.lights, 0u) << "the station's and the truck's lights move every frame";
      expectSceneMatchesWorld(world);
      const uint64_t sceneHash = world.renderScene().stateHash();
      if (referenceScene == 0) referenceScene = sceneHash;
      EXPECT_EQ(sceneHash, referenceScene);
    }
  }
}

TEST(WorldRender, TheRenderThreadsBusyTimeIsInTheProfile) {
  World world(renderScene(), 2);
  for (int f = 0; f < 5; ++f) world.step();
  uint32_t zones = 0;
  std::vector<uint8_t> frames(5, 0);
  for (const ProfileEvent& e : world.profiler().events())
    if (std::string(e.name) == "render thread: apply") {
      ++zones;
      ASSERT_LT(e.frame, 5u);
      frames[e.frame] = 1;
      EXPECT_EQ(e.stage, -1) << "beside the frames, not in their work/span";
      EXPECT_LE(e.beginNs, e.endNs);
    }
  EXPECT_EQ(zones, 5u);
  for (uint8_t seen : frames) EXPECT_EQ(seen, 1);
}

TEST(WorldRender, SleepingAndStaticBodiesSubmitNothing) {
  // Boxes dropped on a static floor: after they sleep, no record is submitted at all.
  const SceneDescription desc = parseScene(R"({
    "name": "sleepers",
    "grids": [{"name": "floor", "bricks": [{"position": [0, 0, -0.5], "half_size": [20, 20, 0.5]}]}],
    "spawners": [{"shape": "box", "count": 20, "half_extents": [0.25, 0.25, 0.25],
                  "region": {"min": [-5, -5, 0.3], "max": [5, 5, 0.6]}, "seed": 9}],
    "attachments": {}
  })", "sleepers.json");
  World world(desc, 2);
  world.step();
  EXPECT_EQ(world.lastStats().render.primitives, world.render()->store().primitiveCount()) << "the first frame sends everything";
  bool allAsleep = false;
  for (int f = 0; f < 600 && !allAsleep; ++f) {
    world.step();
    allAsleep = world.sleepingCount() == 20;
  }
  ASSERT_TRUE(allAsleep);
  for (int f = 0; f < 5; ++f) {
    world.step();
    EXPECT_EQ(world.lastStats().render.primitives + world.lastStats().render.lights, 0u);
    EXPECT_EQ(world.lastStats().render.movedBodies, 0u);
  }
  expectSceneMatchesWorld(world);
}

TEST(WorldRender, BatchOverflowIsReportedKeepsThePreviousSceneAndLeavesPhysicsAlone) {
  SceneDescription small = renderScene();
  small.attachments.batchPrimitives = 10;  // far fewer than the first frame's records
  SceneDescription roomy = renderScene();
  World overflowing(small, 2, SubmissionMode::Batched);
  World reference(roomy, 2, SubmissionMode::Batched);
  const RenderScene empty(overflowing.render()->store().primitiveCount(), overflowing.render()->store().lightAttenuationRadii());
  for (int f = 0; f < 5; ++f) {
    try {
      overflowing.step();
      FAIL() << "frame " << f << " fitted in a 10-record batch";
    } catch (const CapacityExceeded& e) {
      EXPECT_NE(std::string(e.what()).find("primitive update batch"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("capacity 10"), std::string::npos) << e.what();
    }
    reference.step();
    // Nothing of an overflowing frame reaches the render scene: it still holds the state
    // before the first frame (every frame here overflows, since every attachment is resent).
    EXPECT_EQ(overflowing.renderScene().stateHash(), empty.stateHash());
    // The physics is not touched by a render-side failure.
    EXPECT_EQ(overflowing.stateHash(), reference.stateHash());
  }
}

TEST(WorldRender, ASceneWithoutAttachmentsHasNoRenderThread) {
  SceneDescription desc = renderScene();
  desc.attachments = AttachmentsDescription{};
  World world(desc, 1);
  world.step();
  EXPECT_EQ(world.render(), nullptr);
  EXPECT_THROW(world.renderScene(), InvalidInput);
  EXPECT_EQ(world.lastStats().render.primitives, 0u);
}

TEST(WorldRender, AttachmentErrorsNameTheField) {
  auto error = [](const std::string& attachments) {
    try {
      parseScene(R"({"name": "x", "spawners": [{"shape": "sphere", "count": 1, "region": {"min": [0,0,0], "max": [0,0,0]}}],
                     "attachments": )" + attachments + "}", "x.json");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error(R"({"render_chunk": 0})").find("scene.attachments.render_chunk"), std::string::npos);
  EXPECT_NE(error(R"({"render_chunks": 4})").find("unknown field"), std::string::npos);
  EXPECT_NE(error(R"({"batch_capacity": {"primitives": -1}})").find("scene.attachments.batch_capacity.primitives"), std::string::npos);
  EXPECT_NE(error(R"({"grid_lights": 1})").find("true or false"), std::string::npos);
  SceneDescription coded = renderScene();
  coded.attachments.renderChunk = std::nanf("");
  EXPECT_THROW(World(coded, 1), SceneError);
}

}  // namespace
}  // namespace bw
