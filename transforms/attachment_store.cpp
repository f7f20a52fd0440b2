#include "transforms/attachment_store.h"

#include <algorithm>
#include <string>

#include "collision/core/argument_checks.h"
#include "transforms/attachment_math.h"

namespace bw {

uint32_t AttachmentStore::add(uint32_t body, uint32_t parent, const Vec3f& t, const Quatf& r, AttachmentKind kind,
                              uint32_t renderId, const Aabb& bounds, const char* context) {
  requireFinite(t, context, "localTranslation");
  requireUnitQuaternion(r, context, "localRotation");
  if (size() == UINT32_MAX - 1) throw CapacityExceeded(std::string(context) + ": attachment count exceeds 2^32 - 2");
  if (body == UINT32_MAX) throw InvalidInput(std::string(context) + ": body index is UINT32_MAX");
  uint8_t depth = 0;
  if (parent != kInvalidIndex) {
    if (parent >= size())
      throw InvalidInput(std::string(context) + ": parent attachment " + std::to_string(parent) +
                         " does not exist (" + std::to_string(size()) + " attachments)");
    if (body_[parent] != body)
      throw InvalidInput(std::string(context) + ": parent attachment " + std::to_string(parent) +
                         " rides on body " + std::to_string(body_[parent]) + ", not " + std::to_string(body));
    if (depth_[parent] + 1u >= kMaxAttachmentDepth)
      throw InvalidInput(std::string(context) + ": hierarchy deeper than " + std::to_string(kMaxAttachmentDepth));
    depth = static_cast<uint8_t>(depth_[parent] + 1);
    hasChildren_[parent] = 1;
  }
  const uint32_t id = size();
  body_.push_back(body);
  parent_.push_back(parent);
  localTranslation_.push_back(t);
  localRotation_.push_back(r.normalized());
  // note: the first update computes every attachment (localDirty = 1), so the world pose
  // starts at a defined value that the first record reports as its "previous" transform.
  worldTranslation_.push_back(Vec3d::Zero());
  worldRotation_.push_back(Quatf::Identity());
  moved_.push_back(0);
  localDirty_.push_back(1);
  kind_.push_back(kind);
  renderId_.push_back(renderId);
  depth_.push_back(depth);
  localBounds_.push_back(bounds);
  hasChildren_.push_back(0);
  fresh_.push_back(updated_ ? 1 : 0);
  bodiesReferenced_ = std::max(bodiesReferenced_, body + 1);
  orderDirty_ = true;
  return id;
}

uint32_t AttachmentStore::addPrimitive(uint32_t body, uint32_t parent, const Vec3f& localTranslation,
                                       const Quatf& localRotation, const Aabb& localBounds) {
  const char* context = "AttachmentStore::addPrimitive";
  requireFinite(localBounds.min, context, "localBounds.min");
  requireFinite(localBounds.max, context, "localBounds.max");
  if (localBounds.isEmpty()) throw InvalidInput(std::string(context) + ": localBounds is inverted");
  const uint32_t id = add(body, parent, localTranslation, localRotation, AttachmentKind::Primitive, primitiveCount_,
                          localBounds, context);
  ++primitiveCount_;
  return id;
}

uint32_t AttachmentStore::addLight(uint32_t body, uint32_t parent, const Vec3f& localTranslation,
                                   const Quatf& localRotation, float attenuationRadius) {
  const char* context = "AttachmentStore::addLight";
  requireInRange(attenuationRadius, 1e-6, 1e9, context, "attenuationRadius");
  const uint32_t id = add(body, parent, localTranslation, localRotation, AttachmentKind::Light,
                          static_cast<uint32_t>(lightAttenuation_.size()), Aabb{Vec3f::Zero(), Vec3f::Zero()}, context);
  lightAttenuation_.push_back(attenuationRadius);
  return id;
}

void AttachmentStore::markAllDirty() { std::fill(localDirty_.begin(), localDirty_.end(), uint8_t(1)); }

void AttachmentStore::setLocalOffset(uint32_t id, const Vec3f& localTranslation, const Quatf& localRotation) {
  const char* context = "AttachmentStore::setLocalOffset";
  if (id >= size()) throw InvalidInput(std::string(context) + ": attachment " + std::to_string(id) + " does not exist");
  requireFinite(localTranslation, context, "localTranslation");
  requireUnitQuaternion(localRotation, context, "localRotation");
  localTranslation_[id] = localTranslation;
  localRotation_[id] = localRotation.normalized();
  localDirty_[id] = 1;
}

void AttachmentStore::reserve(uint32_t n) {
  body_.reserve(n);
  parent_.reserve(n);
  localTranslation_.reserve(n);
  localRotation_.reserve(n);
  worldTranslation_.reserve(n);
  worldRotation_.reserve(n);
  moved_.reserve(n);
  localDirty_.reserve(n);
  levelOrder_.reserve(n);
  kind_.reserve(n);
  renderId_.reserve(n);
  depth_.reserve(n);
  localBounds_.reserve(n);
  hasChildren_.reserve(n);
  fresh_.reserve(n);
}

namespace {

void requireFiniteOrEmpty(const Aabb& b, const char* context) {
  if (b.isEmpty()) {
    if (b.min.hasNaN() || b.max.hasNaN()) throw InvalidInput(std::string(context) + ": localBounds has NaN");
    return;
  }
  requireFinite(b.min, context, "localBounds.min");
  requireFinite(b.max, context, "localBounds.max");
}

}  // namespace

void AttachmentStore::setPrimitiveBounds(uint32_t id, const Aabb& localBounds) {
  const char* context = "AttachmentStore::setPrimitiveBounds";
  if (id >= size()) throw InvalidInput(std::string(context) + ": attachment " + std::to_string(id) + " does not exist");
  if (kind_[id] != AttachmentKind::Primitive) throw InvalidInput(std::string(context) + ": attachment " + std::to_string(id) + " is a light");
  requireFiniteOrEmpty(localBounds, context);
  localBounds_[id] = localBounds.isEmpty() ? hiddenBounds() : localBounds;
  localDirty_[id] = 1;
}

void AttachmentStore::requireRebindable(uint32_t id, AttachmentKind kind, uint32_t body, const char* context) const {
  if (id >= size()) throw InvalidInput(std::string(context) + ": attachment " + std::to_string(id) + " does not exist");
  if (kind_[id] != kind)
    throw InvalidInput(std::string(context) + ": attachment " + std::to_string(id) + " is a " +
                       (kind_[id] == AttachmentKind::Light ? "light" : "primitive"));
  if (parent_[id] != kInvalidIndex || hasChildren_[id])
    throw InvalidInput(std::string(context) + ": attachment " + std::to_string(id) + " is part of a hierarchy");
  if (body == UINT32_MAX) throw InvalidInput(std::string(context) + ": body index is UINT32_MAX");
}

void AttachmentStore::rebindLight(uint32_t id, uint32_t body) {
  requireRebindable(id, AttachmentKind::Light, body, "AttachmentStore::rebindLight");
  body_[id] = body;
  localDirty_[id] = 1;
  fresh_[id] = 1;
  bodiesReferenced_ = std::max(bodiesReferenced_, body + 1);
}

void AttachmentStore::rebindPrimitive(uint32_t id, uint32_t body, const Vec3f& localTranslation, const Quatf& localRotation,
                                      const Aabb& localBounds) {
  const char* context = "AttachmentStore::rebindPrimitive";
  requireRebindable(id, AttachmentKind::Primitive, body, context);
  requireFinite(localTranslation, context, "localTranslation");
  requireUnitQuaternion(localRotation, context, "localRotation");
  requireFiniteOrEmpty(localBounds, context);
  body_[id] = body;
  localTranslation_[id] = localTranslation;
  localRotation_[id] = localRotation.normalized();
  localBounds_[id] = localBounds.isEmpty() ? hiddenBounds() : localBounds;
  localDirty_[id] = 1;
  fresh_[id] = 1;
  bodiesReferenced_ = std::max(bodiesReferenced_, body + 1);
}

void AttachmentStore::prepareUpdateOrder() {
  if (!orderDirty_) return;
  // Counting sort by depth; ids ascend inside a level, so each level streams the columns
  // front to back.
  uint32_t counts[kMaxAttachmentDepth] = {};
  for (uint8_t d : depth_) ++counts[d];
  levelCount_ = 0;
  uint32_t offset = 0;
  for (uint32_t l = 0; l < kMaxAttachmentDepth; ++l) {
    levelBegin_[l] = offset;
    offset += counts[l];
    if (counts[l] != 0) levelCount_ = l + 1;
  }
  levelBegin_[kMaxAttachmentDepth] = offset;
  levelOrder_.resize(size());
  uint32_t cursor[kMaxAttachmentDepth];
  for (uint32_t l = 0; l < kMaxAttachmentDepth; ++l) cursor[l] = levelBegin_[l];
  for (uint32_t id = 0; id < size(); ++id) levelOrder_[cursor[depth_[id]]++] = id;
  orderDirty_ = false;
}

AttachmentColumns AttachmentStore::columns() {
  updated_ = true;
  return {body_.data(),          parent_.data(),           kind_.data(),          renderId_.data(),
          localTranslation_.data(), localRotation_.data(), localBounds_.data(),   worldTranslation_.data(),
          worldRotation_.data(), moved_.data(),            localDirty_.data(),    fresh_.data(),
          levelOrder_.data()};
}

}  // namespace bw
