// Fuzz target: brick grid edits with contacts. The bytes are a program of brick placements
// (every shape, rotation, size from 0.001 to 10^4, some bad), removals (some of unknown ids),
// batch placements into an empty grid, and contact queries of spheres, boxes, capsules and
// hulls compared feature for feature with brute force over every brick. A refused edit leaves
// the grid as it was; at the end mass properties equal a direct sum and the index is canonical.
#include <algorithm>
#include <map>
#include <vector>

#include "collision/bricks/brick_geometry.h"
#include "collision/bricks/brick_grid.h"
#include "collision/bricks/brick_narrowphase.h"
#include "collision/core/errors.h"
#include "fuzz/box_choices.h"

namespace {

using namespace bw;
using fuzz::FuzzInput;

constexpr uint32_t kCapacity = 256;
constexpr int kMaxOps = 1500;
constexpr std::array<float, 4> kDensities = {1.f, 2.5f, 0.3f, 7.8f};

using Oracle = std::map<uint32_t, Brick>;

Brick fuzzBrick(FuzzInput& in, float anchor) {
  Brick b;
  b.position = fuzz::latticePoint(in, anchor);
  for (int a = 0; a < 3; ++a) b.halfSize[a] = in.pick(std::span<const float>(fuzz::kHalfSizes));
  b.shape = BrickShape(in.below(5));  // 4: not a shape
  b.sides = uint8_t(in.below(70));
  b.rotation = AxisRotation::fromIndex(int(in.below(24)));
  b.filter = 1u << in.below(3);
  b.material = uint8_t(in.below(uint32_t(kDensities.size())));
  if (in.below(32) == 0) (in.flag() ? b.position : b.halfSize)[in.below(3)] = in.rawFloat();
  return b;
}

bool acceptableBrick(const Brick& b) {
  if (!b.position.allFinite() || !b.halfSize.allFinite()) return false;
  for (int a = 0; a < 3; ++a)
    if (b.halfSize[a] < kMinBrickHalfSize || b.halfSize[a] > kMaxBrickHalfSize) return false;
  if (uint8_t(b.shape) > uint8_t(BrickShape::Cylinder)) return false;
  if (b.shape == BrickShape::Cylinder && (b.sides < 3 || b.sides > 64)) return false;
  return fuzz::acceptableBox(brickBounds(b));
}

void place(FuzzInput& in, BrickGrid& grid, Oracle& o, float anchor) {
  const Brick b = fuzzBrick(in, anchor);
  const uint64_t before = acceptableBrick(b) ? 0 : grid.index().structureHash();  // (a walk: only for a bad brick)
  try {
    const uint32_t id = grid.placeBrick(b);
    FUZZ_CHECK(acceptableBrick(b), "placeBrick accepted a bad brick");
    FUZZ_CHECK(!o.count(id), "placeBrick returned live id %u", id);
    o[id] = b;
  } catch (const InvalidInput&) {
    FUZZ_CHECK(!acceptableBrick(b), "placeBrick refused a good brick");
    FUZZ_CHECK(grid.index().structureHash() == before, "a refused placement changed the grid");
  } catch (const CapacityExceeded&) {
    FUZZ_CHECK(o.size() >= kCapacity, "full at %zu of %u bricks", o.size(), kCapacity);
  }
}

void remove(FuzzInput& in, BrickGrid& grid, Oracle& o) {
  uint32_t id = in.u16();
  if (!o.empty() && in.below(8) != 0) {
    auto it = o.begin();
    std::advance(it, in.below(uint32_t(o.size())));
    id = it->first;
  }
  const bool live = o.count(id) != 0;
  try {
    grid.removeBrick(id);
    FUZZ_CHECK(live, "removeBrick accepted unknown id %u", id);
    o.erase(id);
  } catch (const InvalidInput&) {
    FUZZ_CHECK(!live, "removeBrick refused live id %u", id);
  }
}

void placeBatch(FuzzInput& in, BrickGrid& grid, Oracle& o, float anchor) {
  if (!o.empty()) return;
  std::vector<Brick> batch(in.below(64));
  for (Brick& b : batch) b = fuzzBrick(in, anchor);
  const bool good = std::all_of(batch.begin(), batch.end(), acceptableBrick);
  try {
    const std::vector<uint32_t> ids = grid.placeBricks(batch);
    FUZZ_CHECK(good, "placeBricks accepted a bad brick");
    for (size_t i = 0; i < ids.size(); ++i) o[ids[i]] = batch[i];
  } catch (const InvalidInput&) {
    FUZZ_CHECK(!good, "placeBricks refused good bricks");
    FUZZ_CHECK(grid.brickCount() == 0, "a refused batch placed %u bricks", grid.brickCount());
  }
}

struct ContactKey {
  uint32_t feature;
  float depth;
  bool operator<(const ContactKey& k) const { return feature < k.feature || (feature == k.feature && depth < k.depth); }
  bool operator==(const ContactKey&) const = default;
};

void collide(FuzzInput& in, const BrickGrid& grid, float anchor) {
  const float size = in.pick(std::span<const float>(fuzz::kHalfSizes)) + 0.01f;
  std::vector<Vec3f> hull;
  QueryShape shape;
  switch (in.below(4)) {
    case 0: shape = QueryShape::sphere(size); break;
    case 1: shape = QueryShape::box(Vec3f(size, size * in.lattice(0.05f, 1), size * in.lattice(0.05f, 1))); break;
    case 2: shape = QueryShape::capsule(size * in.lattice(0.1f, 1), size); break;
    default:
      for (int i = 0; i < 8; ++i) hull.emplace_back((i & 1) ? size : -size, (i & 2) ? size * 0.6f : -size * 0.6f, (i & 4) ? size * 0.8f : -size * 0.8f);
      hull.emplace_back(0.f, 0.f, size * 1.5f);
      shape = QueryShape::hull(hull.data(), uint32_t(hull.size()));
  }
  const LocalPose pose{fuzz::latticePoint(in, anchor),
                       Quatf(Eigen::AngleAxisf(in.lattice(0, 6.28f), Vec3f(in.lattice(-1, 1), in.lattice(-1, 1), 1.f).normalized()))};
  ContactParams params;
  params.lodFraction = 0.f;
  params.speculativeMargin = in.flag() ? size * 0.1f : 0.f;
  std::vector<LocalContact> got;
  grid.collideLocal(shape, pose, params, got);
  std::vector<ContactKey> a, b;
  LocalContact buf[kMaxContactsPerBrick];
  grid.forEachBrick([&](uint32_t id) {
    const int n = collideShapeBrick(shape, pose, grid.brick(id), id, params.speculativeMargin, buf);
    for (int i = 0; i < n; ++i) b.push_back({buf[i].feature, buf[i].depth});
  });
  for (const LocalContact& c : got) {
    FUZZ_CHECK(c.position.allFinite() && c.normal.allFinite() && std::isfinite(c.depth), "a non-finite contact");
    a.push_back({c.feature, c.depth});
  }
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  FUZZ_CHECK(a == b, "collide found %zu contacts, brute force %zu", a.size(), b.size());
}

void checkFinal(const BrickGrid& grid, const Oracle& o, const BrickGrid::Config& config) {
  grid.index().validate();
  FUZZ_CHECK(grid.brickCount() == o.size(), "grid holds %u bricks, oracle %zu", grid.brickCount(), o.size());
  std::vector<Aabb> bounds;
  std::vector<uint32_t> filters, ids;
  for (const auto& [id, b] : o) {
    bounds.push_back(brickBounds(b));
    filters.push_back(b.filter);
    ids.push_back(id);
  }
  OctoBvh fresh(OctoBvh::Config{kCapacity});
  fresh.bulkLoad(bounds, filters, ids);
  FUZZ_CHECK(fresh.structureHash() == grid.index().structureHash(), "the grid's index differs from a bulk load");
  // The direct sum in two passes: the centre of mass, then the moments about it (no cancellation).
  ShapeMoments first;
  for (const auto& [id, b] : o) first += brickMoments(b, config.density[b.material], Vec3d::Zero());
  const MassProperties m = grid.massProperties();
  FUZZ_CHECK(std::abs(m.mass - first.volume) <= 1e-9 * first.volume, "mass %.17g, direct sum %.17g", m.mass, first.volume);
  if (first.volume <= 0) return;
  const Vec3d com = first.first / first.volume;
  ShapeMoments central;
  for (const auto& [id, b] : o) central += brickMoments(b, config.density[b.material], com);
  FUZZ_CHECK((m.centerOfMass - com).norm() <= 1e-6 * (1 + com.norm()), "centre of mass off by %g", (m.centerOfMass - com).norm());
  const Vec3d comRel = central.first / central.volume;  // ~0, up to rounding
  const Mat3d c = central.second - central.volume * comRel * comRel.transpose();
  const Mat3d inertia = c.trace() * Mat3d::Identity() - c;
  FUZZ_CHECK((m.inertia - inertia).norm() <= 1e-8 * inertia.norm(), "inertia off by %g of %g", (m.inertia - inertia).norm(),
             inertia.norm());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  const float anchor = in.pick(std::span<const float>(fuzz::kAnchors));
  BrickGrid::Config config(kCapacity);
  for (size_t m = 0; m < kDensities.size(); ++m) config.density[m] = kDensities[m];
  BrickGrid grid(config);
  Oracle o;
  for (int op = 0; op < kMaxOps && !in.done(); ++op) {
    switch (in.below(8)) {
      case 0: case 1: case 2: place(in, grid, o, anchor); break;
      case 3: case 4: remove(in, grid, o); break;
      case 5: placeBatch(in, grid, o, anchor); break;
      default: collide(in, grid, anchor);
    }
  }
  checkFinal(grid, o, config);
  return 0;
}
