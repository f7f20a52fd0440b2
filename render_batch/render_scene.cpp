#include "render_batch/render_scene.h"

#include <cstring>
#include <string>

#include "collision/core/argument_checks.h"
#include "collision/core/hash.h"

namespace bw {

// note: byte comparison is only meaningful for padding-free element types.
static_assert(sizeof(Vec3d) == 24 && sizeof(Vec3f) == 12 && sizeof(Mat3f) == 36 && sizeof(Quatf) == 16 &&
              sizeof(Aabb) == 24);

RenderScene::RenderScene(uint32_t primitiveCount, std::vector<float> lightAttenuationRadii)
    : boundsOrigin_(primitiveCount, Vec3d::Zero()),
      boundsExtent_(primitiveCount, Vec3f::Zero()),
      boundsRadius_(primitiveCount, 0.f),
      localBounds_(primitiveCount, Aabb{Vec3f::Zero(), Vec3f::Zero()}),
      linear_(primitiveCount, Mat3f::Identity()),
      translation_(primitiveCount, Vec3d::Zero()),
      previousTranslation_(primitiveCount, Vec3d::Zero()),
      previousRotation_(primitiveCount, Quatf::Identity()),
      lightLinear_(lightAttenuationRadii.size(), Mat3f::Identity()),
      lightTranslation_(lightAttenuationRadii.size(), Vec3d::Zero()),
      lightPosition_(lightAttenuationRadii.size(), Vec3d::Zero()),
      lightInfluenceMin_(lightAttenuationRadii.size(), Vec3d::Zero()),
      lightInfluenceMax_(lightAttenuationRadii.size(), Vec3d::Zero()),
      lightRadius_(lightAttenuationRadii.size(), 0.f),
      lightInvRadius_(lightAttenuationRadii.size(), 0.f),
      lightAttenuation_(std::move(lightAttenuationRadii)) {
  for (uint32_t i = 0; i < lightCount(); ++i) {
    requireInRange(lightAttenuation_[i], 1e-6, 1e9, "RenderScene", "light attenuation radius");
    // A light's radius is set once at registration; motion never changes it.
    applyLightRadius(i);
  }
}

void RenderScene::growPrimitives(uint32_t n) {
  if (n < primitiveCount())
    throw InvalidInput("RenderScene::growPrimitives: " + std::to_string(n) + " proxies asked, the scene has " +
                       std::to_string(primitiveCount()) + " (it never shrinks)");
  boundsOrigin_.resize(n, Vec3d::Zero());
  boundsExtent_.resize(n, Vec3f::Zero());
  boundsRadius_.resize(n, 0.f);
  localBounds_.resize(n, Aabb{Vec3f::Zero(), Vec3f::Zero()});
  linear_.resize(n, Mat3f::Identity());
  translation_.resize(n, Vec3d::Zero());
  previousTranslation_.resize(n, Vec3d::Zero());
  previousRotation_.resize(n, Quatf::Identity());
}

void RenderScene::applyPrimitive(const PrimitiveUpdate& u) {
  if (u.proxyId >= primitiveCount())
    throw InvalidInput("RenderScene::applyPrimitive: proxy " + std::to_string(u.proxyId) + " of " +
                       std::to_string(primitiveCount()));
  const uint32_t i = u.proxyId;
  boundsOrigin_[i] = u.worldBounds.origin;
  boundsExtent_[i] = u.worldBounds.extent;
  boundsRadius_[i] = u.worldBounds.radius;
  localBounds_[i] = u.localBounds;
  linear_[i] = u.localToWorld.linear;
  translation_[i] = u.localToWorld.translation;
  previousTranslation_[i] = u.previousTranslation;
  previousRotation_[i] = u.previousRotation;
}

void RenderScene::applyLight(const LightUpdate& u) {
  if (u.lightId >= lightCount())
    throw InvalidInput("RenderScene::applyLight: light " + std::to_string(u.lightId) + " of " +
                       std::to_string(lightCount()));
  const uint32_t i = u.lightId;
  lightLinear_[i] = u.lightToWorld.linear;
  lightTranslation_[i] = u.lightToWorld.translation;
  lightPosition_[i] = u.position;
  const Vec3d r = Vec3d::Constant(lightRadius_[i]);
  lightInfluenceMin_[i] = u.position - r;
  lightInfluenceMax_[i] = u.position + r;
}

void RenderScene::applyLightRadius(uint32_t lightId) {
  if (lightId >= lightCount())
    throw InvalidInput("RenderScene::applyLightRadius: light " + std::to_string(lightId) + " of " +
                       std::to_string(lightCount()));
  const float radius = lightAttenuation_[lightId];
  lightRadius_[lightId] = radius;
  lightInvRadius_[lightId] = 1.f / radius;
  const Vec3d r = Vec3d::Constant(radius);
  lightInfluenceMin_[lightId] = lightPosition_[lightId] - r;
  lightInfluenceMax_[lightId] = lightPosition_[lightId] + r;
}

template <typename F>
void RenderScene::forEachStateArray(F&& f) const {
  auto bytes = [&f](const auto& v) { f(static_cast<const void*>(v.data()), v.size() * sizeof(v[0])); };
  bytes(boundsOrigin_);
  bytes(boundsExtent_);
  bytes(boundsRadius_);
  bytes(localBounds_);
  bytes(linear_);
  bytes(translation_);
  bytes(previousTranslation_);
  bytes(previousRotation_);
  bytes(lightLinear_);
  bytes(lightTranslation_);
  bytes(lightPosition_);
  bytes(lightInfluenceMin_);
  bytes(lightInfluenceMax_);
  bytes(lightRadius_);
  bytes(lightInvRadius_);
  bytes(lightAttenuation_);
}

bool RenderScene::identicalTo(const RenderScene& other) const {
  if (primitiveCount() != other.primitiveCount() || lightCount() != other.lightCount()) return false;
  std::vector<std::pair<const void*, size_t>> mine, theirs;
  forEachStateArray([&](const void* p, size_t n) { mine.emplace_back(p, n); });
  other.forEachStateArray([&](const void* p, size_t n) { theirs.emplace_back(p, n); });
  for (size_t k = 0; k < mine.size(); ++k)
    if (mine[k].second != theirs[k].second ||
        (mine[k].second != 0 && std::memcmp(mine[k].first, theirs[k].first, mine[k].second) != 0))
      return false;
  return true;
}

uint64_t RenderScene::stateHash() const {
  uint64_t h = 0;
  forEachStateArray([&h](const void* p, size_t n) { h = hashBytes(h, p, n); });
  return h;
}

size_t RenderScene::stateBytes() const {
  size_t total = 0;
  forEachStateArray([&total](const void*, size_t n) { total += n; });
  return total;
}

}  // namespace bw
