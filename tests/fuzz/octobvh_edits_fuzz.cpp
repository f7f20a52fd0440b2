// Fuzz target: OctoBVH edit sequences against a brute-force oracle. The bytes are a program of
// inserts, removes, updates, bulk removals (some of them bad: NaN, inverted, out of range,
// unknown or repeated handles, a full tree) and queries (box, oriented box, closest and all hits along a ray), each answer
// compared with a scan of every element. A refused edit must leave the structure hash as it
// was; at the end the tree validates and hashes equal to a fresh bulk load of its elements.
#include <algorithm>
#include <iterator>
#include <map>
#include <vector>

#include "collision/core/errors.h"
#include "collision/index/octobvh.h"
#include "collision/support/brute_force_index.h"
#include "fuzz/box_choices.h"

namespace {

using namespace bw;
using fuzz::FuzzInput;

constexpr uint32_t kCapacity = 512;  // small, so the fuzzer reaches a full tree
constexpr int kMaxOps = 3000;

struct Oracle {
  test::BruteForceIndex index;
  std::map<uint32_t, uint32_t> payloads;
};

uint32_t liveHandle(FuzzInput& in, const Oracle& o) {
  auto it = o.index.items.begin();
  std::advance(it, in.below(uint32_t(o.index.items.size())));
  return it->first;
}

void insert(FuzzInput& in, OctoBvh& tree, Oracle& o, float anchor, uint32_t payload) {
  const Aabb b = fuzz::fuzzBox(in, anchor);
  const uint32_t filter = 1u << in.below(4);
  // The hash costs a walk of the tree: taken only where a refusal is expected (an unexpected
  // refusal fails the checks below anyway).
  const bool mayRefuse = !fuzz::acceptableBox(b) || tree.size() >= kCapacity / 2;
  const uint64_t before = mayRefuse ? tree.structureHash() : 0;
  try {
    const uint32_t h = tree.insert(b, filter, payload);
    FUZZ_CHECK(fuzz::acceptableBox(b), "insert accepted a bad box");
    FUZZ_CHECK(o.index.items.size() < kCapacity, "insert beyond capacity");
    FUZZ_CHECK(!o.index.items.count(h), "insert returned live handle %u", h);
    o.index.items[h] = {b, filter};
    o.payloads[h] = payload;
  } catch (const InvalidInput&) {
    FUZZ_CHECK(!fuzz::acceptableBox(b), "insert refused a good box");
    FUZZ_CHECK(tree.structureHash() == before, "a refused insert changed the tree");
  } catch (const CapacityExceeded&) {
    FUZZ_CHECK(o.index.items.size() >= kCapacity || tree.size() >= kCapacity / 2,
               "full at %zu of %u elements", o.index.items.size(), kCapacity);
    FUZZ_CHECK(tree.structureHash() == before, "a refused insert changed the tree");
  }
}

void removeOrUpdate(FuzzInput& in, OctoBvh& tree, Oracle& o, float anchor, bool update) {
  const bool known = !o.index.items.empty() && in.below(8) != 0;
  const uint32_t h = known ? liveHandle(in, o) : in.u16();
  const bool live = o.index.items.count(h) != 0;
  const Aabb b = update ? fuzz::fuzzBox(in, anchor) : Aabb{};
  const uint32_t filter = 1u << in.below(4);
  const uint64_t before = !live || (update && !fuzz::acceptableBox(b)) ? tree.structureHash() : 0;
  try {
    if (update) {
      tree.update(h, b, filter);
      FUZZ_CHECK(live && fuzz::acceptableBox(b), "update accepted handle %u (live %d) or a bad box", h, int(live));
      o.index.items[h] = {b, filter};
    } else {
      tree.remove(h);
      FUZZ_CHECK(live, "remove accepted dead handle %u", h);
      o.index.items.erase(h);
      o.payloads.erase(h);
    }
  } catch (const InvalidInput&) {
    FUZZ_CHECK(!live || (update && !fuzz::acceptableBox(b)), "refused a good edit of handle %u", h);
    FUZZ_CHECK(tree.structureHash() == before, "a refused edit changed the tree");
  }
}

// Many elements out at once (removeMany): a random subset or everything on one side of a plane
// (a part breaking off), sometimes with a handle listed twice or a dead one (refused whole).
void removeMany(FuzzInput& in, OctoBvh& tree, Oracle& o) {
  std::vector<uint32_t> gone;
  const int axis = int(in.below(3));
  const bool plane = in.below(2) == 0;
  const float cut = float(in.below(256)) / 255.f;
  const Aabb all = o.index.items.empty() ? Aabb{} : tree.rootBounds();
  const float at = all.min[axis] + cut * (all.max[axis] - all.min[axis]);
  for (const auto& [h, item] : o.index.items)
    if (plane ? item.bounds.center()[axis] < at : in.below(4) != 0) gone.push_back(h);
  const uint32_t bad = in.below(8);
  if (bad == 0 && !gone.empty()) gone.push_back(gone[in.below(uint32_t(gone.size()))]);
  if (bad == 1) gone.push_back(in.u16() + kCapacity);  // never a live handle
  if (bad <= 1 && !gone.empty()) {
    const uint64_t before = tree.structureHash();
    bool refused = false;
    try {
      tree.removeMany(gone);
    } catch (const InvalidInput&) {
      refused = true;
    }
    FUZZ_CHECK(refused, "removeMany accepted a bad list of %zu handles", gone.size());
    FUZZ_CHECK(tree.structureHash() == before, "a refused removeMany changed the tree");
    return;
  }
  tree.removeMany(gone);
  for (uint32_t h : gone) {
    o.index.items.erase(h);
    o.payloads.erase(h);
  }
  FUZZ_CHECK(tree.size() == o.index.items.size(), "removeMany left %u elements, expected %zu", tree.size(), o.index.items.size());
}

void query(FuzzInput& in, const OctoBvh& tree, const Oracle& o, float anchor) {
  const uint32_t mask = 1u + in.below(15);
  std::vector<uint32_t> got;
  switch (in.below(3)) {
    case 0: {
      Aabb box = fuzz::fuzzBox(in, anchor);
      if (!fuzz::acceptableBox(box)) return;
      tree.overlap(box, mask, got);
      std::sort(got.begin(), got.end());
      FUZZ_CHECK(got == o.index.overlap(box, mask), "box overlap: %zu found, brute force %zu", got.size(),
                 o.index.overlap(box, mask).size());
      return;
    }
    case 1: {
      const Aabb box = fuzz::fuzzBox(in, anchor);
      if (!fuzz::acceptableBox(box)) return;
      Obb obb = Obb::fromAabb(box);
      obb.axes = Eigen::AngleAxisf(in.lattice(0, 6.28f), Vec3f(in.lattice(-1, 1), in.lattice(-1, 1), 1.f).normalized())
                     .toRotationMatrix();
      tree.overlap(obb, mask, got);
      std::sort(got.begin(), got.end());
      const std::vector<uint32_t> expected = o.index.overlap(obb, mask);
      if (got != expected) {
        std::vector<uint32_t> missed;
        std::set_difference(expected.begin(), expected.end(), got.begin(), got.end(), std::back_inserter(missed));
        for (uint32_t h : missed) {
          const Aabb& b = o.index.items.at(h).bounds;
          std::fprintf(stderr, "missed %u: (%.9g %.9g %.9g)-(%.9g %.9g %.9g), in the tree %d\n", h, b.min.x(), b.min.y(), b.min.z(),
                       b.max.x(), b.max.y(), b.max.z(), int(tree.contains(h) && tree.bounds(h).min == b.min && tree.bounds(h).max == b.max));
        }
        std::fprintf(stderr, "obb centre (%.9g %.9g %.9g) half (%.9g %.9g %.9g)\n", obb.center.x(), obb.center.y(), obb.center.z(),
                     obb.half.x(), obb.half.y(), obb.half.z());
      }
      FUZZ_CHECK(got == expected, "oriented overlap: %zu found, brute force %zu", got.size(), expected.size());
      return;
    }
    default: {
      const Ray ray = fuzz::fuzzRay(in, anchor);
      const std::vector<RayHit> all = o.index.raycastAll(ray, mask);
      const RayHit closest = tree.raycastClosest(ray, mask);
      FUZZ_CHECK(closest.hit() == !all.empty(), "closest hit %d, brute force hits %zu", int(closest.hit()), all.size());
      if (!all.empty()) {
        // Of hits tied at the closest t, the tree reports the first it meets: any of them.
        bool tied = false;
        for (const RayHit& h : all) tied = tied || (h.t == closest.t && h.element == closest.element);
        FUZZ_CHECK(closest.t == all.front().t && tied, "closest (%u, t %g), brute force (%u, t %g)", closest.element,
                   double(closest.t), all.front().element, double(all.front().t));
      }
      std::vector<RayHit> gotAll;
      tree.raycastAll(ray, mask, gotAll);
      FUZZ_CHECK(gotAll.size() == all.size(), "all hits: %zu, brute force %zu", gotAll.size(), all.size());
      for (size_t i = 0; i < all.size(); ++i)
        FUZZ_CHECK(gotAll[i].element == all[i].element && gotAll[i].t == all[i].t, "hit %zu differs", i);
      return;
    }
  }
}

void checkCanonical(const OctoBvh& tree, const Oracle& o) {
  tree.validate();
  FUZZ_CHECK(tree.size() == o.index.items.size(), "tree holds %u, oracle %zu", tree.size(), o.index.items.size());
  std::vector<Aabb> bounds;
  std::vector<uint32_t> filters, payloads;
  for (const auto& [h, item] : o.index.items) {
    FUZZ_CHECK(tree.payload(h) == o.payloads.at(h), "payload of %u", h);
    bounds.push_back(item.bounds);
    filters.push_back(item.filter);
    payloads.push_back(o.payloads.at(h));
  }
  OctoBvh fresh(OctoBvh::Config{kCapacity});
  fresh.bulkLoad(bounds, filters, payloads);
  FUZZ_CHECK(fresh.structureHash() == tree.structureHash(), "edited tree differs from a bulk load of its %zu elements",
             bounds.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  const float anchor = in.pick(std::span<const float>(fuzz::kAnchors));
  OctoBvh tree(OctoBvh::Config{kCapacity});
  Oracle o;
  uint32_t payload = 0;
  for (int op = 0; op < kMaxOps && !in.done(); ++op) {
    switch (in.below(8)) {
      case 0: case 1: case 2: insert(in, tree, o, anchor, payload++); break;
      case 3: removeOrUpdate(in, tree, o, anchor, /*update*/ false); break;
      case 4: removeOrUpdate(in, tree, o, anchor, /*update*/ true); break;
      case 5: case 6: query(in, tree, o, anchor); break;
      default:
        switch (in.below(16)) {
          case 0: tree.clear(); o = Oracle{}; break;
          case 1: checkCanonical(tree, o); break;
          case 2: case 3: removeMany(in, tree, o); break;
          default: query(in, tree, o, anchor);
        }
    }
  }
  checkCanonical(tree, o);
  return 0;
}
