#pragma once
/// Sink that stores each record in the slot of its render id: concurrent calls never touch
/// the same memory (each id gets at most one record per update), so it costs one copy and
/// nothing else. Used to time the transform update on its own, without a render side.
#include <vector>

#include "transforms/transform_update_sink.h"

namespace bw {

/// Per-render-id record slots (see file comment).
class RecordSlotSink final : public TransformUpdateSink {
 public:
  /// Slots for primitives proxy ids and lights light ids.
  RecordSlotSink(uint32_t primitives, uint32_t lights) : primitives_(primitives), lights_(lights) {}
  /// Copies the record into its proxy's slot.
  void primitive(const PrimitiveUpdate& u) override { primitives_[u.proxyId] = u; }
  /// Copies the record into its light's slot.
  void light(const LightUpdate& u) override { lights_[u.lightId] = u; }
  /// Last record of a proxy (unspecified if it never moved).
  const PrimitiveUpdate& primitiveSlot(uint32_t proxyId) const { return primitives_[proxyId]; }
  /// Last record of a light (unspecified if it never moved).
  const LightUpdate& lightSlot(uint32_t lightId) const { return lights_[lightId]; }

 private:
  std::vector<PrimitiveUpdate> primitives_;
  std::vector<LightUpdate> lights_;
};

}  // namespace bw
