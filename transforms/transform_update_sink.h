#pragma once
/// Where the transform update delivers its records.
///
/// Thread safety: the update calls primitive() and light() (or the block forms) concurrently
/// from worker threads, each record exactly once per moved attachment per frame;
/// implementations must be safe for concurrent calls. The block forms hand over up to
/// TransformUpdate::kRecordBlock records a worker made in a row; by default they deliver them
/// one by one, a sink that can take a block at once (one reservation in a batch) overrides them. Both the SoA update and the object-style baseline use this interface, so
/// a comparison between them measures the layouts, not the delivery.
#include <cstdint>

#include "transforms/transform_records.h"

namespace bw {

/// Receiver of per-frame update records (called from many threads at once).
class TransformUpdateSink {
 public:
  virtual ~TransformUpdateSink() = default;
  /// One moved primitive.
  virtual void primitive(const PrimitiveUpdate& update) = 0;
  /// One moved light.
  virtual void light(const LightUpdate& update) = 0;
  /// count moved primitives in a row.
  virtual void primitives(const PrimitiveUpdate* updates, uint32_t count) {
    for (uint32_t i = 0; i < count; ++i) primitive(updates[i]);
  }
  /// count moved lights in a row.
  virtual void lights(const LightUpdate* updates, uint32_t count) {
    for (uint32_t i = 0; i < count; ++i) light(updates[i]);
  }
};

}  // namespace bw
