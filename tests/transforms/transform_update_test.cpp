// TransformUpdate (SoA, parallel) against an independent serial reference and against the
// object-style baseline: same world poses, same records, only for attachments that moved.
#include <gtest/gtest.h>
#include <ostream>
#include <random>
#include <string>

#include "collision/core/argument_checks.h"
#include "jobs/job_system.h"
#include "transforms/attachment_math.h"
#include "transforms/attachment_workload.h"
#include "transforms/object_style_components.h"
#include "transforms/record_collector.h"
#include "transforms/thread_team_runner.h"
#include "transforms/transform_update.h"

namespace bw {
namespace {

using test::RecordCollector;
using test::sameBytes;

/// Independent reference: recomputes every attachment from its body by walking its parent
/// chain (no level order, no moved-flag propagation), and derives the expected moved set.
struct Reference {
  explicit Reference(const AttachmentStore& s)
      : translation(s.size(), Vec3d::Zero()), rotation(s.size(), Quatf::Identity()), dirty(s.size(), 1),
        moved(s.size(), 0) {}

  void step(const AttachmentStore& s, const BodyPoseView& bodies) {
    previousTranslation = translation;
    previousRotation = rotation;
    for (uint32_t id = 0; id < s.size(); ++id) {
      std::vector<uint32_t> chain;  // id, parent, grandparent, ...
      for (uint32_t a = id; a != kInvalidIndex; a = s.parent(a)) chain.push_back(a);
      const uint32_t body = s.body(id);
      bool m = bodies.moved[body] != 0;
      Vec3d t = bodies.position[body];
      Quatf r = bodies.rotation[body];
      for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
        m = m || dirty[*it];
        Vec3d nt;
        Quatf nr;
        composeAttachmentPose(t, r, s.localTranslation(*it), s.localRotation(*it), nt, nr);
        t = nt;
        r = nr;
      }
      moved[id] = m;
      translation[id] = t;
      rotation[id] = r;
    }
    std::fill(dirty.begin(), dirty.end(), 0);
  }

  std::vector<Vec3d> translation, previousTranslation;
  std::vector<Quatf> rotation, previousRotation;
  std::vector<uint8_t> dirty, moved;
};

/// Frame inputs shared by every run: seeded motion plus, every few frames, local-offset edits.
void applyInputs(AttachmentWorkload& w, Reference* ref, uint64_t frame, float movingFraction) {
  w.bodies.step(frame, movingFraction);
  if (frame % 4 == 0) {
    std::mt19937_64 rng(frame * 977);
    for (int k = 0; k < 5; ++k) {
      const uint32_t id = static_cast<uint32_t>(rng() % w.store.size());
      const Vec3f t = w.store.localTranslation(id) + Vec3f(0.25f, -0.125f, 0.5f);
      w.store.setLocalOffset(id, t, w.store.localRotation(id));
      if (ref) ref->dirty[id] = 1;
    }
  }
}

void expectMatchesReference(const AttachmentStore& s, const Reference& ref, const RecordCollector& records,
                            uint64_t frame) {
  uint32_t movedCount = 0;
  for (uint32_t id = 0; id < s.size(); ++id) {
    ASSERT_TRUE(s.worldTranslation(id) == ref.translation[id]) << "frame " << frame << " attachment " << id;
    ASSERT_TRUE(s.worldRotation(id).coeffs() == ref.rotation[id].coeffs()) << "frame " << frame << " id " << id;
    ASSERT_EQ(s.movedLastUpdate(id), ref.moved[id] != 0) << "frame " << frame << " attachment " << id;
    const uint32_t rid = s.renderId(id);
    if (s.kind(id) == AttachmentKind::Primitive) {
      const uint32_t hits = records.primitiveHits[rid].load();
      ASSERT_EQ(hits, ref.moved[id] ? 1u : 0u) << "frame " << frame << " primitive " << rid;
      if (hits) {
        // Field checks that do not go through attachment_math, then the whole record.
        const PrimitiveUpdate& u = records.primitives[rid];
        ASSERT_TRUE(u.previousTranslation == ref.previousTranslation[id]) << "frame " << frame << " primitive " << rid;
        ASSERT_TRUE(u.previousRotation.coeffs() == ref.previousRotation[id].coeffs()) << "primitive " << rid;
        ASSERT_TRUE(u.localToWorld.translation == ref.translation[id]) << "frame " << frame << " primitive " << rid;
        ASSERT_TRUE(u.localBounds == s.localBounds(id)) << "primitive " << rid;
        ASSERT_TRUE(u.worldBounds.extent.minCoeff() >= 0.f) << "primitive " << rid;
        ASSERT_TRUE(sameBytes(records.primitives[rid],
                              makePrimitiveUpdate(rid, s.localBounds(id), ref.translation[id], ref.rotation[id],
                                                  ref.previousTranslation[id], ref.previousRotation[id])))
            << "frame " << frame << " primitive " << rid;
      }
    } else {
      const uint32_t hits = records.lightHits[rid].load();
      ASSERT_EQ(hits, ref.moved[id] ? 1u : 0u) << "frame " << frame << " light " << rid;
      if (hits) {
        ASSERT_TRUE(sameBytes(records.lights[rid], makeLightUpdate(rid, ref.translation[id], ref.rotation[id])));
      }
    }
    movedCount += ref.moved[id];
  }
  if (frame > 1) {
    EXPECT_GT(movedCount, 0u) << "the test must exercise moved attachments";
    EXPECT_LT(movedCount, s.size()) << "the test must exercise skipped attachments";
  }
}

enum class Runner { Serial, JobSystem2, JobSystem4, ThreadTeam3 };

std::string runnerName(const ::testing::TestParamInfo<Runner>& info) {
  static const char* const kNames[] = {"Serial", "JobSystem2", "JobSystem4", "ThreadTeam3"};
  return kNames[static_cast<int>(info.param)];
}

void PrintTo(Runner r, std::ostream* os) { *os << runnerName(::testing::TestParamInfo<Runner>(r, 0)); }

class TransformUpdateDifferential : public ::testing::TestWithParam<Runner> {};

TEST_P(TransformUpdateDifferential, MatchesSerialReferenceEveryFrame) {
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = 4000, .seed = 21, .maxDepth = 4});
  Reference ref(w.store);
  RecordCollector records(w.store.primitiveCount(), w.store.lightCount());
  JobSystem jobs(GetParam() == Runner::JobSystem4 ? 4 : 2);
  for (uint64_t frame = 1; frame <= 12; ++frame) {
    applyInputs(w, &ref, frame, 0.3f);
    ref.step(w.store, w.bodies.view());
    records.reset();
    TransformUpdate update(w.store, w.bodies.view(), records);
    switch (GetParam()) {
      case Runner::Serial: update.runSerial(); break;
      case Runner::JobSystem2:
      case Runner::JobSystem4: update.run(jobs, 64); break;
      case Runner::ThreadTeam3: test::runOnThreadTeam(update, 3); break;
    }
    expectMatchesReference(w.store, ref, records, frame);
    if (HasFatalFailure()) return;
  }
}

INSTANTIATE_TEST_SUITE_P(Runners, TransformUpdateDifferential,
                         ::testing::Values(Runner::Serial, Runner::JobSystem2, Runner::JobSystem4, Runner::ThreadTeam3),
                         runnerName);

TEST(TransformUpdate, ObjectStyleBaselineProducesIdenticalRecords) {
  const int threads = 2;
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = 3000, .seed = 33, .maxDepth = 3});
  ObjectStyleScene objects(w.store);
  RecordCollector soa(w.store.primitiveCount(), w.store.lightCount());
  RecordCollector obj(w.store.primitiveCount(), w.store.lightCount());
  JobSystem jobs(threads);
  for (uint64_t frame = 1; frame <= 6; ++frame) {
    w.bodies.step(frame, 0.5f);
    soa.reset();
    obj.reset();
    TransformUpdate(w.store, w.bodies.view(), soa).run(jobs, 128);
    objects.update(jobs, w.bodies.view(), obj, 16);
    for (uint32_t id = 0; id < w.store.size(); ++id) {
      ASSERT_TRUE(objects.component(id).worldTranslation() == w.store.worldTranslation(id)) << id;
      ASSERT_TRUE(objects.component(id).worldRotation().coeffs() == w.store.worldRotation(id).coeffs()) << id;
    }
    for (uint32_t p = 0; p < w.store.primitiveCount(); ++p) {
      ASSERT_EQ(soa.primitiveHits[p].load(), obj.primitiveHits[p].load()) << "frame " << frame << " proxy " << p;
      if (soa.primitiveHits[p].load()) {
        ASSERT_TRUE(sameBytes(soa.primitives[p], obj.primitives[p])) << p;
      }
    }
    for (uint32_t l = 0; l < w.store.lightCount(); ++l) {
      ASSERT_EQ(soa.lightHits[l].load(), obj.lightHits[l].load()) << "frame " << frame << " light " << l;
      if (soa.lightHits[l].load()) {
        ASSERT_TRUE(sameBytes(soa.lights[l], obj.lights[l])) << l;
      }
    }
  }
}

TEST(TransformUpdate, LocalOffsetEditRecomputesOnlyThatSubtree) {
  AttachmentStore s;
  const Aabb box = Aabb::fromCenterHalf(Vec3f::Zero(), Vec3f::Ones());
  const uint32_t hull = s.addPrimitive(0, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), box);
  const uint32_t lamp = s.addLight(0, hull, Vec3f(0, 2, 0), Quatf::Identity(), 4.f);
  const uint32_t lens = s.addPrimitive(0, lamp, Vec3f(0, 0.5f, 0), Quatf::Identity(), box);
  const uint32_t other = s.addPrimitive(0, hull, Vec3f(1, 0, 0), Quatf::Identity(), box);
  const Vec3d position[1] = {Vec3d(10, 0, 0)};
  const Quatf rotation[1] = {Quatf(Eigen::AngleAxisf(0.5f, Vec3f::UnitZ()))};
  uint8_t moved[1] = {1};
  RecordCollector records(3, 1);
  TransformUpdate(s, {position, rotation, moved, 1}, records).runSerial();
  EXPECT_TRUE(s.movedLastUpdate(hull) && s.movedLastUpdate(lamp) && s.movedLastUpdate(lens) && s.movedLastUpdate(other));

  moved[0] = 0;
  s.setLocalOffset(lamp, Vec3f(0, 3, 0), Quatf::Identity());
  records.reset();
  TransformUpdate(s, {position, rotation, moved, 1}, records).runSerial();
  EXPECT_FALSE(s.movedLastUpdate(hull));
  EXPECT_TRUE(s.movedLastUpdate(lamp));
  EXPECT_TRUE(s.movedLastUpdate(lens));
  EXPECT_FALSE(s.movedLastUpdate(other));
  EXPECT_EQ(records.primitiveHits[s.renderId(hull)].load(), 0u);
  EXPECT_EQ(records.primitiveHits[s.renderId(lens)].load(), 1u);
  EXPECT_EQ(records.primitiveHits[s.renderId(other)].load(), 0u);
  EXPECT_EQ(records.lightHits[s.renderId(lamp)].load(), 1u);
  // The lamp sits 3 units along the body's rotated y axis.
  const Vec3d expected = position[0] + rotation[0].cast<double>() * Vec3d(0, 3, 0);
  EXPECT_NEAR((s.worldTranslation(lamp) - expected).norm(), 0.0, 1e-6);
  EXPECT_TRUE(records.lights[0].position == s.worldTranslation(lamp));

  records.reset();
  TransformUpdate(s, {position, rotation, moved, 1}, records).runSerial();
  EXPECT_EQ(records.lightHits[0].load(), 0u);  // nothing moved, nothing sent
}

TEST(TransformUpdate, KeepsPrecisionFarFromTheOrigin) {
  AttachmentStore s;
  const uint32_t a = s.addPrimitive(0, kInvalidIndex, Vec3f(0.001f, 0.002f, 0.003f), Quatf::Identity(),
                                    Aabb::fromCenterHalf(Vec3f::Zero(), Vec3f::Ones()));
  const Vec3d position[1] = {Vec3d(1e7, -2e7, 3e7)};
  const Quatf rotation[1] = {Quatf::Identity()};
  const uint8_t moved[1] = {1};
  RecordCollector records(1, 0);
  TransformUpdate(s, {position, rotation, moved, 1}, records).runSerial();
  // note: a double ulp at 3e7 is 3.7e-9; a float world position would be off by whole units.
  EXPECT_NEAR(s.worldTranslation(a).x() - 1e7, 0.001, 1e-8);
  EXPECT_NEAR(s.worldTranslation(a).z() - 3e7, 0.003, 1e-8);
  EXPECT_NEAR(records.primitives[0].worldBounds.origin.y() + 2e7, 0.002, 1e-8);
}

TEST(TransformUpdate, RejectsABodyViewThatDoesNotCoverTheStore) {
  AttachmentStore s;
  s.addPrimitive(5, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(),
                 Aabb::fromCenterHalf(Vec3f::Zero(), Vec3f::Ones()));
  const Vec3d position[2] = {Vec3d::Zero(), Vec3d::Zero()};
  const Quatf rotation[2] = {Quatf::Identity(), Quatf::Identity()};
  const uint8_t moved[2] = {1, 1};
  RecordCollector records(1, 0);
  EXPECT_THROW(TransformUpdate(s, {position, rotation, moved, 2}, records), InvalidInput);
  ObjectStyleScene objects(s);
  JobSystem jobs(1);
  EXPECT_THROW(objects.update(jobs, {position, rotation, moved, 2}, records), InvalidInput);
}

}  // namespace
}  // namespace bw
