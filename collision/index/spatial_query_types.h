#pragma once
/// Types shared by the spatial indices (OctoBVH and the loose-octree baseline): query
/// statistics, ray hits, LOD boxes, and the default exact-element hooks.
#include <cstdint>
#include <limits>

#include "collision/core/aabb.h"
#include "collision/core/ids.h"

namespace bw {

/// Per-query counters. Queries never touch shared counters (they may run on many threads);
/// callers pass their own QueryStats and sum them.
struct QueryStats {
  uint64_t boxTests = 0;        ///< node-bounds and element-bounds intersection tests
  uint64_t elementTests = 0;    ///< of which element tests
  void operator+=(const QueryStats& o) {
    boxTests += o.boxTests;
    elementTests += o.elementTests;
  }
};

/// A ray hit: element handle and ray parameter.
struct RayHit {
  uint32_t element = kInvalidIndex;
  float t = std::numeric_limits<float>::infinity();
  bool hit() const { return element != kInvalidIndex; }
  bool operator<(const RayHit& o) const { return t < o.t || (t == o.t && element < o.element); }
};

/// A subtree reported as one solid box by the collision-LOD overlap.
struct LodBox {
  Aabb bounds;
  uint32_t filter;    ///< OR of the subtree's filter bits
  uint32_t elements;  ///< how many elements it stands for
};

/// Default exact overlap test: the element's AABB (already tested) is the shape.
struct AabbOverlapExact {
  bool operator()(uint32_t, const Aabb&) const { return true; }
};

/// Default exact ray test: the element's AABB is the shape, so the hit is the box entry.
struct AabbRayExact {
  bool operator()(uint32_t, float tEnterBox, float, float& tHit) const {
    tHit = tEnterBox;
    return true;
  }
};

/// Child visiting order for rays: front-to-back (default) or its reverse (for measurements).
enum class RayChildOrder : uint8_t { FrontToBack, Reversed };

}  // namespace bw
