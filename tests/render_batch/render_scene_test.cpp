// RenderScene: applying updates, idempotent radius refresh, byte-identical comparison.
#include <gtest/gtest.h>

#include "collision/core/argument_checks.h"
#include "render_batch/render_scene.h"
#include "transforms/attachment_math.h"

namespace bw {
namespace {

PrimitiveUpdate somePrimitive(uint32_t id, double x) {
  return makePrimitiveUpdate(id, Aabb::fromCenterHalf(Vec3f(0.1f, 0, 0), Vec3f(1, 2, 3)), Vec3d(x, 2, 3),
                             Quatf(Eigen::AngleAxisf(0.3f, Vec3f::UnitY())), Vec3d(x - 1, 2, 3), Quatf::Identity());
}

TEST(RenderScene, ApplyOverwritesTheWholeProxyState) {
  RenderScene a(4, {3.f, 6.f});
  RenderScene b(4, {3.f, 6.f});
  EXPECT_TRUE(a.identicalTo(b));
  a.applyPrimitive(somePrimitive(2, 5));
  EXPECT_FALSE(a.identicalTo(b));
  EXPECT_NE(a.stateHash(), b.stateHash());
  b.applyPrimitive(somePrimitive(2, 9));  // an older value, then the same final value
  b.applyPrimitive(somePrimitive(2, 5));
  EXPECT_TRUE(a.identicalTo(b));
  EXPECT_EQ(a.stateHash(), b.stateHash());
  EXPECT_EQ(a.localToWorldTranslation(2), Vec3d(5, 2, 3));
  EXPECT_EQ(a.previousTranslation(2), Vec3d(4, 2, 3));
}

TEST(RenderScene, LightRadiusRefreshIsIdempotentWork) {
  RenderScene a(0, {3.f, 6.f});
  RenderScene b(0, {3.f, 6.f});
  const LightUpdate u = makeLightUpdate(1, Vec3d(100, 0, -4), Quatf::Identity());
  a.applyLight(u);
  b.applyLight(u);
  b.applyLightRadius(1);  // what the engine sent on every light move
  EXPECT_TRUE(a.identicalTo(b));
  EXPECT_EQ(a.lightRadius(1), 6.f);
  EXPECT_EQ(a.lightInfluenceMin(1), Vec3d(94, -6, -10));
  EXPECT_EQ(a.lightInfluenceMax(1), Vec3d(106, 6, 2));
}

TEST(RenderScene, OneFlippedBitIsNotIdentical) {
  RenderScene a(3, {1.f});
  RenderScene b(3, {1.f});
  PrimitiveUpdate u = somePrimitive(0, 1);
  a.applyPrimitive(u);
  u.worldBounds.radius = std::nextafter(u.worldBounds.radius, 100.f);
  b.applyPrimitive(u);
  EXPECT_FALSE(a.identicalTo(b));
  EXPECT_GT(a.stateBytes(), 0u);
}

TEST(RenderScene, RejectsUnknownIds) {
  RenderScene s(2, {1.f});
  EXPECT_THROW(s.applyPrimitive(somePrimitive(2, 0)), InvalidInput);
  EXPECT_THROW(s.applyLight(makeLightUpdate(1, Vec3d::Zero(), Quatf::Identity())), InvalidInput);
  EXPECT_THROW(s.applyLightRadius(5), InvalidInput);
  EXPECT_THROW(RenderScene(1, {0.f}), InvalidInput);
}

}  // namespace
}  // namespace bw
