// Batching regression tests: per-object (mutex and concurrent queue) and batched submission
// against a serial reference, over many frames of seeded random motion on several threads.
// Checks byte-identical render scenes, exact update counts per frame (nothing lost or
// duplicated), the radius refresh only on the per-object path, the frame fence, and overflow.
#include <gtest/gtest.h>
#include <memory>
#include <ostream>
#include <random>
#include <string>

#include "collision/core/argument_checks.h"
#include "jobs/job_system.h"
#include "render_batch/batched_submitter.h"
#include "render_batch/mutex_command_queue.h"
#include "render_batch/render_frame_pipeline.h"
#include "transforms/attachment_math.h"
#include "transforms/attachment_workload.h"
#include "transforms/thread_team_runner.h"

namespace bw {
namespace {

constexpr uint32_t kAttachments = 5000;
constexpr uint64_t kFrames = 30;
constexpr float kMovingFraction = 0.5f;

AttachmentWorkload makeWorkload() {
  return makeAttachmentWorkload({.attachments = kAttachments, .seed = 2024, .maxDepth = 4});
}

/// The game's inputs for a frame: seeded body motion and a few local-offset edits.
void applyInputs(AttachmentWorkload& w, uint64_t frame) {
  w.bodies.step(frame, kMovingFraction);
  if (frame % 5 == 0) {
    std::mt19937_64 rng(frame * 31337);
    for (int k = 0; k < 8; ++k) {
      const uint32_t id = static_cast<uint32_t>(rng() % w.store.size());
      w.store.setLocalOffset(id, w.store.localTranslation(id) + Vec3f(0.5f, 0.25f, -0.75f), w.store.localRotation(id));
    }
  }
}

/// Serial reference: no render thread, no queue, no batch; records applied as they come.
class DirectApply final : public TransformUpdateSink {
 public:
  explicit DirectApply(RenderScene& scene) : scene_(scene) {}
  void primitive(const PrimitiveUpdate& u) override {
    scene_.applyPrimitive(u);
    ++primitives;
  }
  void light(const LightUpdate& u) override {
    scene_.applyLight(u);
    ++lights;
  }
  uint64_t primitives = 0, lights = 0;

 private:
  RenderScene& scene_;
};

struct ReferenceRun {
  std::vector<uint64_t> hash;        // by frame; [0] = initial scene
  std::vector<uint64_t> primitives;  // moved primitives by frame
  std::vector<uint64_t> lights;      // moved lights by frame
  std::unique_ptr<RenderScene> finalScene;
};

const ReferenceRun& reference() {
  static const ReferenceRun run = [] {
    ReferenceRun r;
    AttachmentWorkload w = makeWorkload();
    r.finalScene = std::make_unique<RenderScene>(w.store.primitiveCount(), w.store.lightAttenuationRadii());
    r.hash.push_back(r.finalScene->stateHash());
    r.primitives.push_back(0);
    r.lights.push_back(0);
    for (uint64_t frame = 1; frame <= kFrames; ++frame) {
      applyInputs(w, frame);
      DirectApply sink(*r.finalScene);
      TransformUpdate(w.store, w.bodies.view(), sink).runSerial();
      r.hash.push_back(r.finalScene->stateHash());
      r.primitives.push_back(sink.primitives);
      r.lights.push_back(sink.lights);
    }
    return r;
  }();
  return run;
}

enum class Runner { JobSystem2, ThreadTeam4 };

struct Case {
  SubmissionMode mode;
  Runner runner;
};

std::string caseLabel(const Case& c) {
  return std::string(submissionModeName(c.mode)) + (c.runner == Runner::JobSystem2 ? "_JobSystem2" : "_ThreadTeam4");
}
std::string caseName(const ::testing::TestParamInfo<Case>& info) { return caseLabel(info.param); }
// Readable (and padding-free) parameter text in test listings.
void PrintTo(const Case& c, std::ostream* os) { *os << caseLabel(c); }

class BatchingDifferential : public ::testing::TestWithParam<Case> {};

TEST_P(BatchingDifferential, MatchesSerialReferenceFrameByFrame) {
  const ReferenceRun& ref = reference();
  const SubmissionMode mode = GetParam().mode;
  AttachmentWorkload w = makeWorkload();
  struct FenceRecord {
    uint64_t hash = 0;
    RenderThreadStats stats;
    uint32_t times = 0;
  };
  // Written by the render thread at each fence, read here after finish() (ordered by the fence).
  std::vector<FenceRecord> fences(kFrames + 1);
  RenderFramePipeline pipeline(w.store, mode, [&fences](uint64_t frame, const RenderScene& scene,
                                                        const RenderThreadStats& stats) {
    if (frame < fences.size()) fences[frame] = {scene.stateHash(), stats, fences[frame].times + 1};
  });
  JobSystem jobs(2);
  for (uint64_t frame = 1; frame <= kFrames; ++frame) {
    applyInputs(w, frame);
    if (GetParam().runner == Runner::JobSystem2)
      pipeline.runFrame(w.bodies.view(), jobs);
    else
      pipeline.runFrame(w.bodies.view(), [](TransformUpdate& u) { test::runOnThreadTeam(u, 4); });
  }
  pipeline.finish();

  // The game-side view after the last fence is byte-identical to the serial reference.
  EXPECT_TRUE(pipeline.renderThread().scene().identicalTo(*ref.finalScene));
  const bool perObject = mode != SubmissionMode::Batched;
  const bool radiusRefresh = sendsLightRadius(mode);
  RenderThreadStats previous;
  for (uint64_t frame = 1; frame <= kFrames; ++frame) {
    const FenceRecord& f = fences[frame];
    ASSERT_EQ(f.times, 1u) << "fence of frame " << frame;
    // At the fence the scene is exactly frame N: nothing of N missing, nothing of N+1 in.
    EXPECT_EQ(f.hash, ref.hash[frame]) << "frame " << frame;
    // Nothing lost or duplicated: the counts match the reference exactly.
    const uint64_t primitives = f.stats.primitiveUpdates - previous.primitiveUpdates;
    const uint64_t lights = f.stats.lightUpdates - previous.lightUpdates;
    const uint64_t radius = f.stats.lightRadiusUpdates - previous.lightRadiusUpdates;
    const uint64_t commands = f.stats.commandsExecuted - previous.commandsExecuted;
    EXPECT_EQ(primitives, ref.primitives[frame]) << "frame " << frame;
    EXPECT_EQ(lights, ref.lights[frame]) << "frame " << frame;
    // The engine's wasted radius refresh is visible on the per-object path that sends it only;
    // the NoRadius modes send exactly one command per update, like the batch's records.
    EXPECT_EQ(radius, radiusRefresh ? ref.lights[frame] : 0u) << "frame " << frame;
    EXPECT_EQ(commands, perObject ? ref.primitives[frame] + (radiusRefresh ? 2 : 1) * ref.lights[frame] + 1 : 1u)
        << "frame " << frame;
    previous = f.stats;
  }
  EXPECT_GT(ref.primitives[kFrames], 1000u);
  EXPECT_GT(ref.lights[kFrames], 100u);
}

INSTANTIATE_TEST_SUITE_P(
    Modes, BatchingDifferential,
    ::testing::Values(Case{SubmissionMode::PerObjectMutex, Runner::JobSystem2},
                      Case{SubmissionMode::PerObjectMutex, Runner::ThreadTeam4},
                      Case{SubmissionMode::PerObjectConcurrent, Runner::JobSystem2},
                      Case{SubmissionMode::PerObjectConcurrent, Runner::ThreadTeam4},
                      Case{SubmissionMode::PerObjectMutexNoRadius, Runner::JobSystem2},
                      Case{SubmissionMode::PerObjectMutexNoRadius, Runner::ThreadTeam4},
                      Case{SubmissionMode::PerObjectConcurrentNoRadius, Runner::JobSystem2},
                      Case{SubmissionMode::PerObjectConcurrentNoRadius, Runner::ThreadTeam4},
                      Case{SubmissionMode::Batched, Runner::JobSystem2},
                      Case{SubmissionMode::Batched, Runner::ThreadTeam4}),
    caseName);

TEST(OwedWakes, FramesReachTheirFencesWhetherAWorkerWakesTheRenderThreadOrNoOne) {
  // The world's way: the commit leaves the wake owed and a worker delivers it beside the next
  // frame. In the first four frames and every third one after nobody delivers it: the next
  // frame, or finish() for the last, must. A pipeline
  // that dropped an owed wake would hang here (the render thread asleep, the game waiting).
  const ReferenceRun& ref = reference();
  for (SubmissionMode mode : {SubmissionMode::Batched, SubmissionMode::PerObjectMutex}) {
    AttachmentWorkload w = makeWorkload();
    std::vector<uint64_t> fenceHash(kFrames + 1, 0);
    RenderFramePipeline pipeline(w.store, mode, [&fenceHash](uint64_t frame, const RenderScene& scene, const RenderThreadStats&) {
      if (frame < fenceHash.size()) fenceHash[frame] = scene.stateHash();
    });
    JobSystem jobs(2);
    for (uint64_t frame = 1; frame <= kFrames; ++frame) {
      jobs.joinBeside();
      applyInputs(w, frame);
      pipeline.runFrame(w.bodies.view(), [&jobs](TransformUpdate& u) { u.run(jobs); }, /*wakeOwed*/ true);
      if (frame > 4 && frame % 3 != 0) jobs.runBeside([&pipeline] { pipeline.wakeRenderThread(); });
    }
    jobs.joinBeside();
    pipeline.finish();
    EXPECT_TRUE(pipeline.renderThread().scene().identicalTo(*ref.finalScene)) << submissionModeName(mode);
    for (uint64_t frame = 1; frame <= kFrames; ++frame)
      EXPECT_EQ(fenceHash[frame], ref.hash[frame]) << submissionModeName(mode) << " frame " << frame;
  }
}

TEST(FrameFence, GameNeverSeesTheNextFrameBeforeItCommits) {
  const ReferenceRun& ref = reference();
  AttachmentWorkload w = makeWorkload();
  RenderThread render(RenderScene(w.store.primitiveCount(), w.store.lightAttenuationRadii()),
                      std::make_unique<MutexCommandQueue>());
  BatchedSubmitter submitter(render, w.store.primitiveCount(), w.store.lightCount());
  for (uint64_t frame = 1; frame <= 12; ++frame) {
    applyInputs(w, frame);
    submitter.beginFrame(frame);
    TransformUpdate update(w.store, w.bodies.view(), submitter);
    test::runOnThreadTeam(update, 3);
    // Frame N's records are in the batch, not committed: the render side still shows N-1.
    render.waitForFrame(frame - 1);
    ASSERT_EQ(render.completedFrame(), frame - 1);
    ASSERT_EQ(render.scene().stateHash(), ref.hash[frame - 1]) << "frame " << frame << " leaked before commit";
    submitter.commitFrame(frame);
    render.waitForFrame(frame);
    ASSERT_EQ(render.scene().stateHash(), ref.hash[frame]) << "frame " << frame << " incomplete after its fence";
  }
}

TEST(BatchOverflow, IsReportedAndLeavesTheSceneAtTheLastGoodFrame) {
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = 2000, .seed = 9});
  const uint32_t capacity = w.store.primitiveCount() / 2;
  RenderFramePipeline pipeline(w.store, SubmissionMode::Batched, {}, capacity, w.store.lightCount());
  w.bodies.step(1, 1.f);
  try {
    pipeline.runFrame(w.bodies.view(), [](TransformUpdate& u) { test::runOnThreadTeam(u, 4); });
    FAIL() << "overflow was not reported";
  } catch (const CapacityExceeded& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("primitive update batch"), std::string::npos) << message;
    EXPECT_NE(message.find("capacity " + std::to_string(capacity)), std::string::npos) << message;
    EXPECT_NE(message.find(std::to_string(w.store.primitiveCount()) + " appended"), std::string::npos) << message;
  }
  pipeline.finish();  // the overflowing frame still closed its fence
  EXPECT_EQ(pipeline.renderThread().completedFrame(), 1u);
  const RenderScene untouched(w.store.primitiveCount(), w.store.lightAttenuationRadii());
  EXPECT_TRUE(pipeline.renderThread().scene().identicalTo(untouched));
}

// Batches of exactly the store's primitive and light counts, with every body moving (so every
// primitive is appended every frame): no overflow, and the render scene after each frame is
// byte-identical to a serial reference run of the same workload (a batch one short would throw,
// IsReportedAndLeavesTheSceneAtTheLastGoodFrame; one that silently dropped or duplicated a record
// would differ here).
TEST(BatchOverflow, ExactCapacityIsEnough) {
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = 2000, .seed = 9});
  AttachmentWorkload refWorkload = makeAttachmentWorkload({.attachments = 2000, .seed = 9});
  RenderScene refScene(refWorkload.store.primitiveCount(), refWorkload.store.lightAttenuationRadii());
  const uint64_t initialHash = refScene.stateHash();
  RenderFramePipeline pipeline(w.store, SubmissionMode::Batched, {}, w.store.primitiveCount(), w.store.lightCount());
  for (uint64_t frame = 1; frame <= 3; ++frame) {
    w.bodies.step(frame, 1.f);
    refWorkload.bodies.step(frame, 1.f);
    DirectApply sink(refScene);
    TransformUpdate(refWorkload.store, refWorkload.bodies.view(), sink).runSerial();
    EXPECT_EQ(sink.primitives, w.store.primitiveCount()) << "frame " << frame << ": not every primitive moved";
    EXPECT_NO_THROW(pipeline.runFrame(w.bodies.view(), [](TransformUpdate& u) { test::runOnThreadTeam(u, 2); }));
    pipeline.renderThread().waitForFrame(frame);
    EXPECT_EQ(pipeline.renderThread().scene().stateHash(), refScene.stateHash()) << "frame " << frame;
  }
  pipeline.finish();
  EXPECT_NE(refScene.stateHash(), initialHash) << "the reference never moved";
  EXPECT_TRUE(pipeline.renderThread().scene().identicalTo(refScene));
}

// A store edited between frames the way the world edits it for brick edits and splits:
// primitives added (the render scene and a batch that follows the store grow before the frame's
// records), hidden (empty bounds), rebound to other bodies. Every mode ends byte-identical to a
// serial reference that grows its scene by hand; nothing is lost across the growth.
TEST(StoreGrowth, AddedHiddenAndReboundPrimitivesReachTheRenderSceneInEveryMode) {
  for (SubmissionMode mode : {SubmissionMode::Batched, SubmissionMode::PerObjectMutex, SubmissionMode::PerObjectConcurrent}) {
    AttachmentWorkload w = makeAttachmentWorkload({.attachments = 3000, .seed = 77, .maxDepth = 3});
    AttachmentWorkload ref = makeAttachmentWorkload({.attachments = 3000, .seed = 77, .maxDepth = 3});
    RenderScene refScene(ref.store.primitiveCount(), ref.store.lightAttenuationRadii());
    RenderFramePipeline pipeline(w.store, mode);
    std::mt19937 rng(5);
    const uint32_t bodies = w.store.bodiesReferenced();
    for (uint64_t frame = 1; frame <= 12; ++frame) {
      if (frame % 3 == 0) {
        // The same edits on both stores: 150 new primitives on random bodies, 40 hidden, 40
        // hidden ones rebound elsewhere.
        const uint32_t first = w.store.size();
        for (int k = 0; k < 150; ++k) {
          const uint32_t body = rng() % bodies;
          const Aabb box{Vec3f(-1, -2, -0.5f), Vec3f(1, 2, float(k % 7))};
          w.store.addPrimitive(body, kInvalidIndex, Vec3f(float(k), 0, 1), Quatf::Identity(), box);
          ref.store.addPrimitive(body, kInvalidIndex, Vec3f(float(k), 0, 1), Quatf::Identity(), box);
        }
        for (int k = 0; k < 40; ++k) {
          const uint32_t id = first + k;
          w.store.setPrimitiveBounds(id, Aabb::empty());
          ref.store.setPrimitiveBounds(id, Aabb::empty());
        }
        for (int k = 0; k < 40; k += 2) {
          const uint32_t id = first + k, body = rng() % bodies;
          w.store.rebindPrimitive(id, body, Vec3f(3, 2, 1), Quatf::Identity(), Aabb{-Vec3f::Ones(), Vec3f::Ones()});
          ref.store.rebindPrimitive(id, body, Vec3f(3, 2, 1), Quatf::Identity(), Aabb{-Vec3f::Ones(), Vec3f::Ones()});
        }
        refScene.growPrimitives(ref.store.primitiveCount());
      }
      w.bodies.step(frame, kMovingFraction);
      ref.bodies.step(frame, kMovingFraction);
      DirectApply sink(refScene);
      TransformUpdate(ref.store, ref.bodies.view(), sink).runSerial();
      ASSERT_NO_THROW(pipeline.runFrame(w.bodies.view(), [](TransformUpdate& u) { test::runOnThreadTeam(u, 2); }))
          << submissionModeName(mode);
    }
    pipeline.finish();
    const RenderScene& scene = pipeline.renderThread().scene();
    ASSERT_EQ(scene.primitiveCount(), w.store.primitiveCount()) << submissionModeName(mode);
    EXPECT_TRUE(scene.identicalTo(refScene)) << submissionModeName(mode);
    uint32_t hidden = 0;
    for (uint32_t id = 0; id < scene.primitiveCount(); ++id) hidden += !scene.visible(id);
    EXPECT_EQ(hidden, 80u) << submissionModeName(mode) << ": 4 rounds each hid 40 and gave 20 of them back";
  }
}

TEST(StoreGrowth, LightsAddedOnceTheRenderThreadRunsAreRefusedAndScenesNeverShrink) {
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = 200, .seed = 3});
  RenderFramePipeline pipeline(w.store, SubmissionMode::Batched);
  pipeline.runFrame(w.bodies.view(), [](TransformUpdate& u) { u.runSerial(); });
  w.store.addLight(0, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), 4.f);
  try {
    pipeline.runFrame(w.bodies.view(), [](TransformUpdate& u) { u.runSerial(); });
    ADD_FAILURE() << "a light added after the start was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("lights cannot be added"), std::string::npos) << e.what();
  }
  EXPECT_EQ(pipeline.frame(), 1u) << "nothing was submitted";
  RenderScene scene(10, {});
  EXPECT_THROW(scene.growPrimitives(9), InvalidInput);
  scene.growPrimitives(12);
  EXPECT_EQ(scene.primitiveCount(), 12u);
  EXPECT_TRUE(scene.visible(11));
}

TEST(RenderThread, ErrorOnTheRenderThreadReachesTheGame) {
  RenderThread render(RenderScene(2, {}), std::make_unique<MutexCommandQueue>());
  render.enqueue(makePrimitiveUpdate(7, Aabb::fromCenterHalf(Vec3f::Zero(), Vec3f::Ones()), Vec3d::Zero(),
                                     Quatf::Identity(), Vec3d::Zero(), Quatf::Identity()));
  render.endFrame(1);
  EXPECT_THROW(render.waitForFrame(1), InvalidInput);
}

}  // namespace
}  // namespace bw
