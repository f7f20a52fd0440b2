#pragma once
/// SoA store of attachments: render primitives and lights riding on bodies with local offsets.
///
///   AttachmentStore store;
///   uint32_t hull  = store.addPrimitive(body, kInvalidIndex, offset, rot, localBox);
///   uint32_t lamp  = store.addLight(body, hull, lampOffset, Quatf::Identity(), 12.f);  // rides on hull
///
/// Layout: one array per field, indexed by attachment id (a stable 32-bit handle). Hot fields
/// the update touches every frame (parent links, local offset, world pose, moved flags) are
/// separate from cold ones (kind, render id, bounds) so a frame streams only what it needs.
/// Hierarchy: an attachment rides either directly on a body or on another attachment of the
/// same body, at most kMaxAttachmentDepth levels deep. The update walks attachments level by
/// level (all depth-0 first, then depth-1, ...), so a parent's world pose is final before any
/// child reads it, without locks. The level order is rebuilt only when attachments are added.
/// Render ids: primitives get proxy ids 0..primitiveCount-1 and lights light ids
/// 0..lightCount-1 in creation order; those are the render scene's indices.
/// Hidden primitives: a primitive whose local bounds are empty (stored as hiddenBounds(),
/// attachment_math.h) is sent with zero
/// extent when it is hidden, and the render scene reports it invisible; while it stays hidden
/// its moves are not sent (nothing of it is drawn).
/// Motion vectors: the first update reports the origin as every attachment's previous pose (the
/// object-style baseline does the same); an attachment added or rebound after that reports its
/// first pose as its previous one, so a part split off does not streak from the origin or from
/// the body its reused proxy rode before. The world hides the render chunk of a cell
/// whose bricks are all gone and later rebinds it to whatever needs a new chunk, so a store
/// grows only to the most chunks ever visible at once.
/// Thread safety: edits (add*, set*, rebind*) only while no update runs.
#include <cstdint>
#include <vector>

#include "collision/core/aabb.h"
#include "collision/core/ids.h"
#include "collision/core/math_types.h"

namespace bw {

/// Parent value for an attachment that rides directly on its body.
/// Deepest hierarchy allowed (a body's attachment chain is short in practice: hull -> lamp).
inline constexpr uint32_t kMaxAttachmentDepth = 8;

/// What an attachment renders as.
enum class AttachmentKind : uint8_t { Primitive = 0, Light = 1 };

/// Raw column pointers the transform update reads and writes (valid until the next edit).
struct AttachmentColumns {
  const uint32_t* body;            ///< body each attachment (chain) rides on
  const uint32_t* parent;          ///< parent attachment or kInvalidIndex
  const AttachmentKind* kind;      ///< primitive or light
  const uint32_t* renderId;        ///< proxy id or light id
  const Vec3f* localTranslation;   ///< offset in the parent's frame
  const Quatf* localRotation;      ///< rotation relative to the parent
  const Aabb* localBounds;         ///< primitive bounds in its own frame (empty for lights)
  Vec3d* worldTranslation;         ///< world pose, written by the update
  Quatf* worldRotation;            ///< world rotation, written by the update
  uint8_t* moved;                  ///< 1 if recomputed this frame (children read it)
  uint8_t* localDirty;             ///< 1 if the local offset changed since the last update
  uint8_t* fresh;                  ///< 1 until the first record of an attachment added or rebound after the first update
  const uint32_t* levelOrder;      ///< attachment ids sorted by (depth, id)
};

/// SoA attachment store (see file comment).
class AttachmentStore {
 public:
  /// Adds a render primitive; throws InvalidInput on a bad parent, non-finite or inverted input.
  uint32_t addPrimitive(uint32_t body, uint32_t parent, const Vec3f& localTranslation, const Quatf& localRotation,
                        const Aabb& localBounds);
  /// Adds a light with its attenuation radius (> 0); same checks as addPrimitive.
  uint32_t addLight(uint32_t body, uint32_t parent, const Vec3f& localTranslation, const Quatf& localRotation,
                    float attenuationRadius);
  /// Changes a local offset; the attachment and its subtree are recomputed on the next update.
  void setLocalOffset(uint32_t id, const Vec3f& localTranslation, const Quatf& localRotation);
  /// Changes a primitive's local bounds (empty = hidden); resent on the next update. Throws
  /// InvalidInput for a light, an unknown id or NaN bounds.
  void setPrimitiveBounds(uint32_t id, const Aabb& localBounds);
  /// Moves a primitive that rides directly on its body and carries no children to another body
  /// with a new offset and bounds (empty = hidden); resent on the next update. Throws
  /// InvalidInput otherwise.
  void rebindPrimitive(uint32_t id, uint32_t body, const Vec3f& localTranslation, const Quatf& localRotation,
                       const Aabb& localBounds);
  /// Moves a light that rides directly on its body and carries no children to another body,
  /// keeping its offset (a lamp on a part split off a grid, whose frame is the grid's); resent
  /// on the next update. Throws InvalidInput otherwise.
  void rebindLight(uint32_t id, uint32_t body);
  /// Recomputes and resends every attachment on the next update (after a frame the render side
  /// never applied, e.g. a batch overflow, so the render scene catches up in one frame).
  void markAllDirty();
  /// Reserves room for n attachments (setup-time allocation, keeps add* from reallocating).
  void reserve(uint32_t n);

  /// Number of attachments.
  uint32_t size() const { return static_cast<uint32_t>(body_.size()); }
  /// Number of primitives (= render proxies needed).
  uint32_t primitiveCount() const { return primitiveCount_; }
  /// Number of lights (= render lights needed).
  uint32_t lightCount() const { return static_cast<uint32_t>(lightAttenuation_.size()); }
  /// Highest body index referenced plus one (the update checks the body view covers it).
  uint32_t bodiesReferenced() const { return bodiesReferenced_; }
  /// Attenuation radius of every light, by light id (the render scene registers lights with it).
  const std::vector<float>& lightAttenuationRadii() const { return lightAttenuation_; }

  /// Primitive or light.
  AttachmentKind kind(uint32_t id) const { return kind_[id]; }
  /// Proxy id (primitives) or light id (lights).
  uint32_t renderId(uint32_t id) const { return renderId_[id]; }
  /// Body the attachment's chain rides on.
  uint32_t body(uint32_t id) const { return body_[id]; }
  /// Parent attachment, or kInvalidIndex.
  uint32_t parent(uint32_t id) const { return parent_[id]; }
  /// Hierarchy level (0 = rides directly on the body).
  uint32_t depth(uint32_t id) const { return depth_[id]; }
  /// Offset in the parent's frame.
  const Vec3f& localTranslation(uint32_t id) const { return localTranslation_[id]; }
  /// Rotation relative to the parent.
  const Quatf& localRotation(uint32_t id) const { return localRotation_[id]; }
  /// Primitive bounds in its own frame (a zero box for lights).
  const Aabb& localBounds(uint32_t id) const { return localBounds_[id]; }
  /// World translation after the last update.
  const Vec3d& worldTranslation(uint32_t id) const { return worldTranslation_[id]; }
  /// World rotation after the last update.
  const Quatf& worldRotation(uint32_t id) const { return worldRotation_[id]; }
  /// 1 if the last update recomputed this attachment.
  bool movedLastUpdate(uint32_t id) const { return moved_[id] != 0; }

  /// Rebuilds the level order if attachments were added (allocates only then).
  void prepareUpdateOrder();
  /// Number of hierarchy levels present (valid after prepareUpdateOrder).
  uint32_t levelCount() const { return levelCount_; }
  /// [levelBegin(l), levelBegin(l + 1)) are the positions of level l in the level order.
  uint32_t levelBegin(uint32_t level) const { return levelBegin_[level]; }
  /// Column pointers for the update (valid until the next add*).
  AttachmentColumns columns();

 private:
  uint32_t add(uint32_t body, uint32_t parent, const Vec3f& t, const Quatf& r, AttachmentKind kind,
               uint32_t renderId, const Aabb& bounds, const char* context);
  // Checks that id is a root attachment of `kind` with no children that may move to body.
  void requireRebindable(uint32_t id, AttachmentKind kind, uint32_t body, const char* context) const;

  // hot: read or written by every update
  std::vector<uint32_t> body_;              // 4 per attachment
  std::vector<uint32_t> parent_;            // 4
  std::vector<Vec3f> localTranslation_;     // 12
  std::vector<Quatf> localRotation_;        // 16
  std::vector<Vec3d> worldTranslation_;     // 24
  std::vector<Quatf> worldRotation_;        // 16
  std::vector<uint8_t> moved_;              // 1
  std::vector<uint8_t> localDirty_;         // 1
  std::vector<uint32_t> levelOrder_;        // 4
  // cold: read only for moved attachments or at setup
  std::vector<AttachmentKind> kind_;
  std::vector<uint32_t> renderId_;
  std::vector<uint8_t> depth_;
  std::vector<Aabb> localBounds_;
  std::vector<uint8_t> hasChildren_;        // 1 once another attachment rides on it
  std::vector<uint8_t> fresh_;              // see AttachmentColumns::fresh
  bool updated_ = false;                    // columns() was taken for an update
  std::vector<float> lightAttenuation_;     // by light id

  uint32_t levelBegin_[kMaxAttachmentDepth + 1] = {};
  uint32_t levelCount_ = 0;
  uint32_t primitiveCount_ = 0;
  uint32_t bodiesReferenced_ = 0;
  bool orderDirty_ = false;
};

}  // namespace bw
