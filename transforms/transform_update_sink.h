#pragma once
/// Where the transform update delivers its records.
///
/// Thread safety: the update calls primitive() and light() concurrently from worker threads,
/// each record exactly once per moved attachment per frame; implementations must be safe for
/// concurrent calls. Both the SoA update and the object-style baseline use this interface, so
/// a comparison between them measures the layouts, not the delivery.
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
};

}  // namespace bw
