#pragma once
// Test sink: keeps each record in its own slot and counts deliveries per id, so a lost or
// duplicated record is visible. Safe for concurrent calls on distinct ids (what the update
// guarantees); the per-id counters are atomics so a duplicate is counted, not raced.
#include <atomic>
#include <cstring>
#include <memory>
#include <vector>

#include "transforms/transform_update_sink.h"

namespace bw::test {

class RecordCollector final : public TransformUpdateSink {
 public:
  RecordCollector(uint32_t primitives, uint32_t lights)
      : primitives(primitives), lights(lights), primitiveHits(new std::atomic<uint32_t>[primitives]),
        lightHits(new std::atomic<uint32_t>[lights]), primitiveCount_(primitives), lightCount_(lights) {
    reset();
  }
  void primitive(const PrimitiveUpdate& u) override {
    if (primitiveHits[u.proxyId].fetch_add(1) == 0) primitives[u.proxyId] = u;
  }
  void light(const LightUpdate& u) override {
    if (lightHits[u.lightId].fetch_add(1) == 0) lights[u.lightId] = u;
  }
  void reset() {
    for (uint32_t i = 0; i < primitiveCount_; ++i) primitiveHits[i] = 0;
    for (uint32_t i = 0; i < lightCount_; ++i) lightHits[i] = 0;
  }

  std::vector<PrimitiveUpdate> primitives;
  std::vector<LightUpdate> lights;
  std::unique_ptr<std::atomic<uint32_t>[]> primitiveHits;
  std::unique_ptr<std::atomic<uint32_t>[]> lightHits;

 private:
  uint32_t primitiveCount_;
  uint32_t lightCount_;
};

/// Byte comparison of two plain records (they have no implicit padding).
template <typename T>
bool sameBytes(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

}  // namespace bw::test
