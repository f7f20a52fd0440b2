#include "transforms/attachment_workload.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "collision/core/argument_checks.h"
#include "collision/core/hash.h"

namespace bw {
namespace {

/// Uniform double in [0, 1) from 53 random bits (portable, unlike std distributions).
double unit(uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

/// Uniform in [lo, hi) from a generator.
double uniform(std::mt19937_64& rng, double lo, double hi) { return lo + (hi - lo) * unit(rng()); }

// note: every draw in its own statement: function arguments are evaluated in an unspecified
// order (GCC right to left, clang left to right), so Quatf(draw(), draw(), ...) differs by compiler.
Quatf randomRotation(std::mt19937_64& rng) {
  const float w = static_cast<float>(uniform(rng, -1, 1));
  const float x = static_cast<float>(uniform(rng, -1, 1));
  const float y = static_cast<float>(uniform(rng, -1, 1));
  const float z = static_cast<float>(uniform(rng, -1, 1));
  Quatf q(w, x, y, z);
  if (q.squaredNorm() < 1e-6f) return Quatf::Identity();
  return q.normalized();
}

Vec3f randomVec(std::mt19937_64& rng, double lo, double hi) {
  const float x = static_cast<float>(uniform(rng, lo, hi));
  const float y = static_cast<float>(uniform(rng, lo, hi));
  const float z = static_cast<float>(uniform(rng, lo, hi));
  return Vec3f(x, y, z);
}

}  // namespace

BodyMotion::BodyMotion(uint32_t count, uint64_t seed, double extent, const Vec3d& offset) : seed_(seed) {
  std::mt19937_64 rng(splitmix64(seed ^ 0x626f646965730000ull));
  position_.reserve(count);
  rotation_.reserve(count);
  velocity_.reserve(count);
  spin_.reserve(count);
  moved_.assign(count, 0);
  for (uint32_t i = 0; i < count; ++i) {
    position_.push_back(offset + Vec3d(uniform(rng, -extent, extent), uniform(rng, -extent, extent),
                                       uniform(rng, -extent, extent)));
    rotation_.push_back(randomRotation(rng));
    velocity_.push_back(randomVec(rng, -0.5, 0.5));
    const Vec3f axis = randomVec(rng, -1, 1);
    const float angle = static_cast<float>(uniform(rng, -0.05, 0.05));
    spin_.push_back(axis.squaredNorm() < 1e-6f ? Quatf::Identity()
                                               : Quatf(Eigen::AngleAxisf(angle, axis.normalized())));
  }
}

void BodyMotion::step(uint64_t frame, float movingFraction) {
  uint32_t movedCount = 0;
  const uint64_t frameKey = splitmix64(seed_ ^ splitmix64(frame));
  for (uint32_t i = 0; i < count(); ++i) {
    const bool move = unit(splitmix64(frameKey + i)) < movingFraction;
    moved_[i] = move ? 1 : 0;
    if (!move) continue;
    ++movedCount;
    position_[i] += velocity_[i].cast<double>();
    rotation_[i] = (rotation_[i] * spin_[i]).normalized();
  }
  movedCount_ = movedCount;
}

void BodyMotion::markAllMoved() {
  std::fill(moved_.begin(), moved_.end(), 1);
  movedCount_ = count();
}

AttachmentWorkload makeAttachmentWorkload(const AttachmentWorkloadDesc& desc) {
  const char* context = "makeAttachmentWorkload";
  if (desc.maxDepth < 1 || desc.maxDepth > kMaxAttachmentDepth)
    throw InvalidInput(std::string(context) + ": maxDepth " + std::to_string(desc.maxDepth) + " outside 1.." +
                       std::to_string(kMaxAttachmentDepth));
  requireInRange(desc.lightFraction, 0, 1, context, "lightFraction");
  requireInRange(desc.childFraction, 0, 1, context, "childFraction");
  requireInRange(desc.worldExtent, 0, 1e12, context, "worldExtent");
  requireFinite(desc.worldOffset, context, "worldOffset");

  std::mt19937_64 rng(splitmix64(desc.seed));
  AttachmentStore store;
  store.reserve(desc.attachments);
  std::vector<uint32_t> bodyAttachments;  // attachments of the body being built
  uint32_t bodies = 0;
  while (store.size() < desc.attachments) {
    const uint32_t body = bodies++;
    bodyAttachments.clear();
    // Every body carries a root primitive (its hull), then 0..4 more attachments.
    const Vec3f half = randomVec(rng, 0.25, 4.0);
    bodyAttachments.push_back(
        store.addPrimitive(body, kInvalidIndex, randomVec(rng, -0.5, 0.5), randomRotation(rng),
                           Aabb::fromCenterHalf(randomVec(rng, -0.2, 0.2), half)));
    const uint32_t extra = static_cast<uint32_t>(rng() % 5);
    for (uint32_t k = 0; k < extra && store.size() < desc.attachments; ++k) {
      uint32_t parent = kInvalidIndex;
      if (unit(rng()) < desc.childFraction) {
        const uint32_t candidate = bodyAttachments[rng() % bodyAttachments.size()];
        if (store.depth(candidate) + 1 < desc.maxDepth) parent = candidate;
      }
      const Vec3f offset = randomVec(rng, -3.0, 3.0);
      const Quatf rot = randomRotation(rng);
      if (unit(rng()) < desc.lightFraction)
        bodyAttachments.push_back(
            store.addLight(body, parent, offset, rot, static_cast<float>(uniform(rng, 2.0, 40.0))));
      else
        bodyAttachments.push_back(store.addPrimitive(
            body, parent, offset, rot, Aabb::fromCenterHalf(randomVec(rng, -0.1, 0.1), randomVec(rng, 0.05, 1.0))));
    }
  }
  BodyMotion motion(bodies, desc.seed, desc.worldExtent, desc.worldOffset);
  return {std::move(store), std::move(motion)};
}

}  // namespace bw
