// AttachmentStore: input validation, render ids, hierarchy levels.
#include <cmath>
#include <gtest/gtest.h>
#include <limits>

#include "collision/core/argument_checks.h"
#include "transforms/attachment_store.h"
#include "transforms/attachment_workload.h"

namespace bw {
namespace {

const Aabb kBox = Aabb::fromCenterHalf(Vec3f::Zero(), Vec3f::Constant(1.f));

TEST(AttachmentStore, AssignsRenderIdsPerKindInCreationOrder) {
  AttachmentStore s;
  const uint32_t a = s.addPrimitive(0, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), kBox);
  const uint32_t b = s.addLight(0, a, Vec3f::UnitX(), Quatf::Identity(), 5.f);
  const uint32_t c = s.addPrimitive(1, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), kBox);
  const uint32_t d = s.addLight(1, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), 7.f);
  EXPECT_EQ(s.renderId(a), 0u);
  EXPECT_EQ(s.renderId(c), 1u);
  EXPECT_EQ(s.renderId(b), 0u);
  EXPECT_EQ(s.renderId(d), 1u);
  EXPECT_EQ(s.primitiveCount(), 2u);
  EXPECT_EQ(s.lightCount(), 2u);
  EXPECT_EQ(s.bodiesReferenced(), 2u);
  EXPECT_EQ(s.lightAttenuationRadii(), (std::vector<float>{5.f, 7.f}));
  EXPECT_EQ(s.depth(b), 1u);
}

TEST(AttachmentStore, RejectsBadInputWithoutStoringIt) {
  AttachmentStore s;
  const uint32_t root = s.addPrimitive(3, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), kBox);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(s.addPrimitive(3, 7, Vec3f::Zero(), Quatf::Identity(), kBox), InvalidInput);      // no such parent
  EXPECT_THROW(s.addPrimitive(4, root, Vec3f::Zero(), Quatf::Identity(), kBox), InvalidInput);   // other body
  EXPECT_THROW(s.addPrimitive(3, root, Vec3f(nan, 0, 0), Quatf::Identity(), kBox), InvalidInput);
  EXPECT_THROW(s.addPrimitive(3, root, Vec3f::Zero(), Quatf(2, 0, 0, 0), kBox), InvalidInput);
  EXPECT_THROW(s.addPrimitive(3, root, Vec3f::Zero(), Quatf::Identity(), Aabb::empty()), InvalidInput);
  EXPECT_THROW(s.addLight(3, root, Vec3f::Zero(), Quatf::Identity(), 0.f), InvalidInput);
  EXPECT_THROW(s.setLocalOffset(99, Vec3f::Zero(), Quatf::Identity()), InvalidInput);
  EXPECT_EQ(s.size(), 1u);
  EXPECT_EQ(s.primitiveCount(), 1u);
  EXPECT_EQ(s.lightCount(), 0u);
}

TEST(AttachmentStore, LimitsHierarchyDepth) {
  AttachmentStore s;
  uint32_t parent = kInvalidIndex;
  for (uint32_t d = 0; d < kMaxAttachmentDepth; ++d)
    parent = s.addPrimitive(0, parent, Vec3f::UnitX(), Quatf::Identity(), kBox);
  EXPECT_EQ(s.depth(parent), kMaxAttachmentDepth - 1);
  EXPECT_THROW(s.addPrimitive(0, parent, Vec3f::UnitX(), Quatf::Identity(), kBox), InvalidInput);
}

TEST(AttachmentStore, LevelOrderPutsParentsInEarlierLevels) {
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = 3000, .seed = 11, .maxDepth = 4});
  AttachmentStore& s = w.store;
  s.prepareUpdateOrder();
  ASSERT_EQ(s.size(), 3000u);
  ASSERT_GE(s.levelCount(), 3u);  // the workload does build hierarchies
  const AttachmentColumns c = s.columns();
  std::vector<uint32_t> seen(s.size(), 0);
  std::vector<uint32_t> levelOf(s.size(), 0);
  for (uint32_t l = 0; l < s.levelCount(); ++l)
    for (uint32_t k = s.levelBegin(l); k < s.levelBegin(l + 1); ++k) {
      const uint32_t id = c.levelOrder[k];
      ++seen[id];
      levelOf[id] = l;
      EXPECT_EQ(s.depth(id), l);
      if (k > s.levelBegin(l)) {
        EXPECT_LT(c.levelOrder[k - 1], id);  // ascending ids inside a level
      }
    }
  for (uint32_t id = 0; id < s.size(); ++id) {
    EXPECT_EQ(seen[id], 1u);
    if (s.parent(id) != kInvalidIndex) {
      EXPECT_LT(levelOf[s.parent(id)], levelOf[id]);
    }
  }
}

TEST(AttachmentWorkload, IsAFunctionOfTheSeed) {
  AttachmentWorkload a = makeAttachmentWorkload({.attachments = 500, .seed = 5});
  AttachmentWorkload b = makeAttachmentWorkload({.attachments = 500, .seed = 5});
  AttachmentWorkload c = makeAttachmentWorkload({.attachments = 500, .seed = 6});
  ASSERT_EQ(a.store.size(), 500u);
  ASSERT_EQ(a.bodies.count(), b.bodies.count());
  bool differs = a.bodies.count() != c.bodies.count();
  for (uint32_t i = 0; i < 500; ++i) {
    EXPECT_EQ(a.store.parent(i), b.store.parent(i));
    EXPECT_EQ(a.store.localTranslation(i), b.store.localTranslation(i));
    differs |= a.store.localTranslation(i) != c.store.localTranslation(i);
  }
  a.bodies.step(4, 0.5f);
  b.bodies.step(4, 0.5f);
  EXPECT_EQ(a.bodies.movedCount(), b.bodies.movedCount());
  EXPECT_GT(a.bodies.movedCount(), 0u);
  EXPECT_LT(a.bodies.movedCount(), a.bodies.count());
  for (uint32_t i = 0; i < a.bodies.count(); ++i) EXPECT_EQ(a.bodies.view().position[i], b.bodies.view().position[i]);
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace bw
