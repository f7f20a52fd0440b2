#include "collision/content/build_generators.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <span>

#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"

namespace bw {
namespace {

constexpr float kStud = 0.4f;          // side of a 1x1 brick
constexpr float kBrickHeight = 0.48f;  // height of a standard brick
constexpr float kPlateHeight = 0.16f;  // height of a plate
constexpr float kMicro = 0.08f;        // side of a microbrick

constexpr int kPosX = AxisRotation::PosX, kNegX = AxisRotation::NegX, kPosY = AxisRotation::PosY,
              kNegY = AxisRotation::NegY, kPosZ = AxisRotation::PosZ, kNegZ = AxisRotation::NegZ;

AxisRotation rotation(int direction, int spin) { return AxisRotation::fromDirectionSpin(direction, spin); }

// Rounds to a multiple of `step`, never below `minValue`: dimensions stay on the brick lattice.
float snap(float v, float step, float minValue) { return std::max(minValue, std::round(v / step) * step); }

bool strictlyInside(const Aabb& box, const Vec3f& p) {
  return (p.array() > box.min.array()).all() && (p.array() < box.max.array()).all();
}

// Collects bricks, or only counts them: every generator body runs twice (count, then write)
// so the output vector is allocated exactly once.
class BuildWriter {
 public:
  explicit BuildWriter(GeneratedBuild* out) : out_(out) {}

  uint32_t count() const { return count_; }

  // Starts a named part; every brick added from now on belongs to it.
  void part(const char* name, uint32_t filter = kBuildFilterStructure) {
    filter_ = filter;
    if (!out_) return;
    closePart();
    out_->parts.push_back({name, count_, count_});
  }
  void finish() { closePart(); }

  void interior(const Aabb& box) {
    if (out_) out_->interiors.push_back(box);
  }
  void ring(const RingDimensions& r) {
    if (out_) out_->ring = r;
  }

  // `worldHalf` is the half extent in the grid; the brick's own half size is derived from the
  // rotation, so callers think in grid axes whatever the brick's orientation.
  void add(const Vec3f& center, const Vec3f& worldHalf, BuildMaterial material,
           BrickShape shape = BrickShape::Box, AxisRotation rot = AxisRotation::identity(), uint8_t sides = 16) {
    ++count_;
    if (!out_) return;
    Brick b;
    b.position = center;
    b.halfSize = rot.inverse().applyToExtent(worldHalf);
    b.filter = filter_;
    b.material = uint8_t(material);
    b.rotation = rot;
    b.shape = shape;
    b.sides = sides;
    out_->bricks.push_back(b);
  }
  void addBox(const Vec3f& lo, const Vec3f& hi, BuildMaterial material) {
    const Vec3f half = (hi - lo) * 0.5f;
    // note: bricks long along Y are stored long along their local X and spun a quarter turn,
    // the way a player places them, which also spreads rotations over the build.
    add((lo + hi) * 0.5f, half, material, BrickShape::Box,
        half.y() > half.x() ? rotation(kPosZ, 1) : AxisRotation::identity());
  }
  // A vertical cylinder standing on `base` (centre of its bottom face).
  void addPillar(const Vec3f& base, float radius, float height, BuildMaterial material, uint8_t sides = 16) {
    add(base + Vec3f(0, 0, height * 0.5f), Vec3f(radius, radius, height * 0.5f), material, BrickShape::Cylinder,
        AxisRotation::identity(), sides);
  }

 private:
  void closePart() {
    if (out_ && !out_->parts.empty()) out_->parts.back().end = count_;
  }
  GeneratedBuild* out_;
  uint32_t count_ = 0;
  uint32_t filter_ = kBuildFilterStructure;
};

// Tiles the box [lo, hi] with boxes close to `cell` (stretched so that a whole number fits
// exactly), leaving out cells whose centre is strictly inside one of `holes`. With
// bondAxis >= 0 every other layer along Z is shifted by half a cell along that axis (running
// bond), so its first and last bricks are half bricks. Neighbours share their boundary values
// exactly, so the tiles touch without overlapping.
void tile(BuildWriter& w, const Vec3f& lo, const Vec3f& hi, const Vec3f& cell, BuildMaterial material,
          std::span<const Aabb> holes = {}, int bondAxis = -1) {
  int n[3];
  float step[3];
  for (int a = 0; a < 3; ++a) {
    n[a] = std::max(1, int(std::lround((hi[a] - lo[a]) / cell[a])));
    step[a] = (hi[a] - lo[a]) / float(n[a]);
  }
  auto boundary = [&](int a, int t, int segments, bool shifted) {
    if (t == 0) return lo[a];
    if (t == segments) return hi[a];
    return lo[a] + (shifted ? float(t) - 0.5f : float(t)) * step[a];
  };
  for (int k = 0; k < n[2]; ++k) {
    const bool shifted = bondAxis >= 0 && (k & 1) != 0;
    const int segY = n[1] + (shifted && bondAxis == 1 ? 1 : 0);
    const int segX = n[0] + (shifted && bondAxis == 0 ? 1 : 0);
    const float z0 = boundary(2, k, n[2], false), z1 = boundary(2, k + 1, n[2], false);
    for (int j = 0; j < segY; ++j) {
      const bool sy = shifted && bondAxis == 1;
      const float y0 = boundary(1, j, segY, sy), y1 = boundary(1, j + 1, segY, sy);
      for (int i = 0; i < segX; ++i) {
        const bool sx = shifted && bondAxis == 0;
        const Vec3f blo(boundary(0, i, segX, sx), y0, z0), bhi(boundary(0, i + 1, segX, sx), y1, z1);
        const Vec3f c = (blo + bhi) * 0.5f;
        bool open = false;
        for (const Aabb& h : holes) open = open || strictlyInside(h, c);
        if (!open) w.addBox(blo, bhi, material);
      }
    }
  }
}

// A wall one brick thick between lo and hi, bricks laid along its longer horizontal axis.
void wall(BuildWriter& w, const Vec3f& lo, const Vec3f& hi, float brickLength, float brickHeight,
          BuildMaterial material, std::span<const Aabb> holes = {}) {
  const int along = (hi.x() - lo.x() >= hi.y() - lo.y()) ? 0 : 1;
  Vec3f cell;
  cell[along] = brickLength;
  cell[1 - along] = hi[1 - along] - lo[1 - along];
  cell[2] = brickHeight;
  tile(w, lo, hi, cell, material, holes, along);
}

// A hip roof over [x0, x1] x [y0, y1] starting at z0: level k is a ring of wedges (corner
// wedges at its four corners) inset by k slots, resting on a ring of boxes one slot further
// in, so the roof is a stepped shell one brick thick. Narrow tops are closed with boxes.
void hipRoof(BuildWriter& w, float x0, float x1, float y0, float y1, float z0, float slot, float rise,
             BuildMaterial material) {
  const int nx = std::max(1, int(std::lround((x1 - x0) / slot)));
  const int ny = std::max(1, int(std::lround((y1 - y0) / slot)));
  const float sx = (x1 - x0) / float(nx), sy = (y1 - y0) / float(ny);
  auto cellLo = [&](int i, int j, int k) { return Vec3f(x0 + float(i) * sx, y0 + float(j) * sy, z0 + float(k) * rise); };
  const Vec3f half(sx * 0.5f, sy * 0.5f, rise * 0.5f);
  for (int k = 0;; ++k) {
    const int i0 = k, i1 = nx - 1 - k, j0 = k, j1 = ny - 1 - k;
    if (i1 - i0 < 2 || j1 - j0 < 2) {
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          const Vec3f lo = cellLo(i, j, k);
          w.addBox(lo, lo + half * 2.f, material);
        }
      return;
    }
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const bool edgeX = i == i0 || i == i1, edgeY = j == j0 || j == j1;
        const bool innerRing = !edgeX && !edgeY && (i == i0 + 1 || i == i1 - 1 || j == j0 + 1 || j == j1 - 1);
        const Vec3f c = cellLo(i, j, k) + half;
        if (edgeX && edgeY) {
          // Canonical corner wedge slopes face +X and +Y; spin it to face out of this corner.
          const int spin = (i == i1) ? (j == j1 ? 0 : 3) : (j == j1 ? 1 : 2);
          w.add(c, half, material, BrickShape::CornerWedge, rotation(kPosZ, spin));
        } else if (edgeX || edgeY) {
          // Canonical wedge slope faces +X; spins 1, 2, 3 face +Y, -X, -Y.
          const int spin = edgeX ? (i == i1 ? 0 : 2) : (j == j1 ? 1 : 3);
          w.add(c, half, material, BrickShape::Wedge, rotation(kPosZ, spin));
        } else if (innerRing) {
          w.addBox(c - half, c + half, material);
        }
      }
  }
}

// Small furniture of 1x1 bricks, plates and microbricks on a 0.4 lattice, placed without
// overlap inside a room's floor rectangle.
class FurniturePlacer {
 public:
  FurniturePlacer(float x0, float y0, int cellsX, int cellsY, float floorZ)
      : x0_(x0), y0_(y0), nx_(cellsX), ny_(cellsY), z_(floorZ), used_(size_t(std::max(0, cellsX * cellsY)), 0) {}

  void furnish(BuildWriter& w, SeededRandom& rng, int items) {
    for (int attempt = 0; attempt < items * 4 && items > 0; ++attempt) {
      const int kind = int(rng.below(5));
      // Footprints in cells (long side first: along X unless alongY): table, chair, bed, shelf, lamp.
      static constexpr int kFootprint[5][2] = {{3, 2}, {1, 1}, {5, 2}, {3, 1}, {1, 1}};
      const bool alongY = rng.below(2) == 1;
      const int fx = alongY ? kFootprint[kind][1] : kFootprint[kind][0];
      const int fy = alongY ? kFootprint[kind][0] : kFootprint[kind][1];
      if (fx > nx_ || fy > ny_) continue;
      const int ci = int(rng.below(uint32_t(nx_ - fx + 1))), cj = int(rng.below(uint32_t(ny_ - fy + 1)));
      if (!reserve(ci, cj, fx, fy)) continue;
      const Vec3f o(x0_ + float(ci) * kStud, y0_ + float(cj) * kStud, z_);
      const Vec3f size(float(fx) * kStud, float(fy) * kStud, 0.f);
      switch (kind) {
        case 0: table(w, rng, o, size); break;
        case 1: chair(w, o); break;
        case 2: bed(w, o, size, alongY); break;
        case 3: shelf(w, o, size, alongY); break;
        default: lamp(w, o); break;
      }
      --items;
    }
  }

 private:
  // Marks the footprint plus a one-cell margin (so items keep a gap) if it is all free.
  bool reserve(int ci, int cj, int fx, int fy) {
    for (int j = std::max(0, cj - 1); j < std::min(ny_, cj + fy + 1); ++j)
      for (int i = std::max(0, ci - 1); i < std::min(nx_, ci + fx + 1); ++i)
        if (used_[size_t(j * nx_ + i)]) return false;
    for (int j = cj; j < cj + fy; ++j)
      for (int i = ci; i < ci + fx; ++i) used_[size_t(j * nx_ + i)] = 1;
    return true;
  }
  static void table(BuildWriter& w, SeededRandom& rng, const Vec3f& o, const Vec3f& size) {
    const float legH = 2.f * kBrickHeight;
    for (int c = 0; c < 4; ++c) {
      const Vec3f lo = o + Vec3f((c & 1) ? size.x() - kStud : 0.f, (c & 2) ? size.y() - kStud : 0.f, 0.f);
      tile(w, lo, lo + Vec3f(kStud, kStud, legH), Vec3f(kStud, kStud, kBrickHeight), BuildMaterial::Wood);
    }
    const Vec3f top = o + Vec3f(0, 0, legH);
    tile(w, top, top + Vec3f(size.x(), size.y(), kPlateHeight), Vec3f(kStud, kStud, kPlateHeight), BuildMaterial::Wood);
    // A cup: a small cylinder on a random top cell.
    const int cx = int(rng.below(uint32_t(std::lround(size.x() / kStud))));
    const int cy = int(rng.below(uint32_t(std::lround(size.y() / kStud))));
    w.addPillar(top + Vec3f((float(cx) + 0.5f) * kStud, (float(cy) + 0.5f) * kStud, kPlateHeight), 0.08f, 0.16f,
                BuildMaterial::Plastic, 12);
  }
  static void chair(BuildWriter& w, const Vec3f& o) {
    w.addBox(o, o + Vec3f(kStud, kStud, kBrickHeight), BuildMaterial::Wood);
    const Vec3f seat = o + Vec3f(0, 0, kBrickHeight);
    w.addBox(seat, seat + Vec3f(kStud, kStud, kPlateHeight), BuildMaterial::Wood);
    const Vec3f back = seat + Vec3f(0, kStud - kMicro, kPlateHeight);
    w.addBox(back, back + Vec3f(kStud, kMicro, 4.f * kPlateHeight), BuildMaterial::Wood);
  }
  static void bed(BuildWriter& w, const Vec3f& o, const Vec3f& size, bool alongY) {
    tile(w, o, o + Vec3f(size.x(), size.y(), kBrickHeight), Vec3f(kStud, kStud, kBrickHeight), BuildMaterial::Wood);
    // Mattress of plates, with the last row along the bed replaced by a headboard of bricks.
    const Vec3f m = o + Vec3f(0, 0, kBrickHeight);
    const Vec3f head = alongY ? Vec3f(size.x(), kStud, 0.f) : Vec3f(kStud, size.y(), 0.f);
    const Vec3f mattressHi = m + Vec3f(size.x(), size.y(), kPlateHeight) - (alongY ? Vec3f(0, kStud, 0) : Vec3f(kStud, 0, 0));
    tile(w, m, mattressHi, Vec3f(kStud, kStud, kPlateHeight), BuildMaterial::Plastic);
    const Vec3f headLo = m + (alongY ? Vec3f(0, size.y() - kStud, 0) : Vec3f(size.x() - kStud, 0, 0));
    tile(w, headLo, headLo + head + Vec3f(0, 0, 2.f * kBrickHeight), Vec3f(kStud, kStud, kBrickHeight), BuildMaterial::Wood);
    // Pillow: a wedge sloping away from the headboard.
    const Vec3f pillowLo = headLo - (alongY ? Vec3f(0, kStud, 0) : Vec3f(kStud, 0, 0)) + Vec3f(0, 0, kPlateHeight);
    const Vec3f pillowHalf = alongY ? Vec3f(size.x() * 0.5f, kStud * 0.5f, kMicro) : Vec3f(kStud * 0.5f, size.y() * 0.5f, kMicro);
    w.add(pillowLo + pillowHalf, pillowHalf, BuildMaterial::Plastic, BrickShape::Wedge,
          rotation(kPosZ, alongY ? 3 : 2));
  }
  static void shelf(BuildWriter& w, const Vec3f& o, const Vec3f& size, bool alongY) {
    const float height = 4.f * kBrickHeight;
    const Vec3f step = alongY ? Vec3f(0, kStud, 0) : Vec3f(kStud, 0, 0);
    const Vec3f post = Vec3f(kStud, kStud, height);
    tile(w, o, o + post, Vec3f(kStud, kStud, kBrickHeight), BuildMaterial::Wood);
    const Vec3f far = o + step * (std::lround((alongY ? size.y() : size.x()) / kStud) - 1);
    tile(w, far, far + post, Vec3f(kStud, kStud, kBrickHeight), BuildMaterial::Wood);
    const Vec3f mid = o + step;
    for (int level = 0; level < 4; ++level) {
      const Vec3f board = mid + Vec3f(0, 0, float(level) * kBrickHeight);
      w.addBox(board, board + Vec3f(kStud, kStud, kPlateHeight), BuildMaterial::Wood);
      // Books: four 0.08-thick boxes standing on the board, across the shelf's length.
      for (int b = 0; b < 4; ++b) {
        const Vec3f across = alongY ? Vec3f(0, float(b) * kMicro + 0.04f, 0) : Vec3f(float(b) * kMicro + 0.04f, 0, 0);
        const Vec3f lo = board + across + Vec3f(0, 0, kPlateHeight);
        const Vec3f bookSize = alongY ? Vec3f(kStud, kMicro, 0.24f) : Vec3f(kMicro, kStud, 0.24f);
        w.addBox(lo, lo + bookSize, BuildMaterial::Plastic);
      }
    }
  }
  static void lamp(BuildWriter& w, const Vec3f& o) {
    const Vec3f base = o + Vec3f(kStud * 0.5f, kStud * 0.5f, 0.f);
    w.addPillar(base, 0.16f, kMicro, BuildMaterial::Metal);
    for (int s = 0; s < 3; ++s) w.addPillar(base + Vec3f(0, 0, kMicro + float(s) * kBrickHeight), 0.04f, kBrickHeight, BuildMaterial::Metal, 8);
    w.addPillar(base + Vec3f(0, 0, kMicro + 3.f * kBrickHeight), 0.2f, 0.24f, BuildMaterial::Glass, 12);
  }

  float x0_, y0_;
  int nx_, ny_;
  float z_;
  std::vector<uint8_t> used_;
};

// Windows along a wall [lo, hi] every `pitch`, each `width` wide, spanning [z0, z1].
void addWindows(std::vector<Aabb>& holes, const Vec3f& lo, const Vec3f& hi, float pitch, float width, float z0,
                float z1) {
  const int along = (hi.x() - lo.x() >= hi.y() - lo.y()) ? 0 : 1;
  const float length = hi[along] - lo[along];
  const int count = int(length / pitch);
  const float margin = (length - float(count) * pitch) * 0.5f;
  for (int k = 0; k < count; ++k) {
    const float c = lo[along] + margin + (float(k) + 0.5f) * pitch;
    Aabb h{lo - Vec3f::Constant(0.01f), hi + Vec3f::Constant(0.01f)};
    h.min[along] = c - width * 0.5f;
    h.max[along] = c + width * 0.5f;
    h.min.z() = z0;
    h.max.z() = z1;
    holes.push_back(h);
  }
}

// Four walls around [x0, x1] x [y0, y1] from z0 to z1, thickness one stud; the X-walls own the
// corners. Windows every `pitch` on every wall; `door` (if any) is also cut.
void perimeterWalls(BuildWriter& w, std::vector<Aabb>& holes, float x0, float x1, float y0, float y1, float z0, float z1,
                    float brickLength, float brickHeight, BuildMaterial material, float pitch, float winZ0, float winZ1,
                    const std::optional<Aabb>& door) {
  const std::array<std::array<Vec3f, 2>, 4> walls = {{
      {Vec3f(x0, y0, z0), Vec3f(x1, y0 + kStud, z1)},
      {Vec3f(x0, y1 - kStud, z0), Vec3f(x1, y1, z1)},
      {Vec3f(x0, y0 + kStud, z0), Vec3f(x0 + kStud, y1 - kStud, z1)},
      {Vec3f(x1 - kStud, y0 + kStud, z0), Vec3f(x1, y1 - kStud, z1)},
  }};
  for (const auto& wl : walls) {
    holes.clear();
    addWindows(holes, wl[0], wl[1], pitch, pitch * 0.5f, winZ0, winZ1);
    if (door) holes.push_back(*door);
    wall(w, wl[0], wl[1], brickLength, brickHeight, material, holes);
  }
}

void computeBounds(GeneratedBuild& b) {
  Aabb box = Aabb::empty();
  for (const Brick& brick : b.bricks) {
    const Vec3f h = brick.rotation.applyToExtent(brick.halfSize);
    box.merge(Aabb{brick.position - h, brick.position + h});
  }
  b.bounds = box;
}

template <class Body>
GeneratedBuild runBuild(const char* name, Body&& body) {
  BuildWriter counter(nullptr);
  body(counter);
  GeneratedBuild out;
  out.name = name;
  out.bricks.reserve(counter.count());
  BuildWriter writer(&out);
  body(writer);
  writer.finish();
  computeBounds(out);
  return out;
}

// ---------------------------------------------------------------------------------- house

void houseBody(BuildWriter& w, uint64_t seed, float scale) {
  SeededRandom rng(seed);
  const float s = std::sqrt(scale);
  const float width = snap(12.f * s, 1.6f, 6.4f), depth = snap(9.6f * s, 1.6f, 4.8f);
  const int storeys = std::max(1, int(std::lround(1.8f * s)));
  const float storeyH = 6.f * kBrickHeight + kPlateHeight;  // walls include the floor layer
  const float margin = 1.6f;

  w.part("baseplate");
  tile(w, Vec3f(-margin, -margin, -kPlateHeight), Vec3f(width + margin, depth + margin, 0.f), Vec3f(6.4f, 6.4f, kPlateHeight),
       BuildMaterial::Concrete);

  std::vector<Aabb> holes;
  holes.reserve(64);
  const float doorX = snap(width * 0.5f, kStud, 0.f);
  const float partitionX = snap(width * (0.4f + 0.2f * float(rng.unit())), kStud, 2.f * kStud);
  for (int st = 0; st < storeys; ++st) {
    const float z0 = float(st) * storeyH, z1 = z0 + storeyH;
    w.part("floor");
    tile(w, Vec3f(kStud, kStud, z0), Vec3f(width - kStud, depth - kStud, z0 + kPlateHeight), Vec3f(0.8f, kStud, kPlateHeight),
         BuildMaterial::Wood);
    w.part("walls");
    std::optional<Aabb> door;
    if (st == 0) door = Aabb{Vec3f(doorX - 0.6f, -0.1f, z0 + kPlateHeight), Vec3f(doorX + 0.6f, kStud + 0.1f, z0 + 2.4f)};
    perimeterWalls(w, holes, 0.f, width, 0.f, depth, z0, z1, kStud, kBrickHeight, BuildMaterial::Masonry, 2.4f,
                   z0 + 1.f, z0 + 2.4f, door);
    // Partition wall between two rooms, with a doorway near one end.
    holes.clear();
    const float doorY = kStud + 0.8f + float(rng.below(2)) * (depth - 3.2f);
    holes.push_back(Aabb{Vec3f(partitionX - 0.1f, doorY, z0), Vec3f(partitionX + kStud + 0.1f, doorY + 1.2f, z0 + 2.4f)});
    wall(w, Vec3f(partitionX, kStud, z0 + kPlateHeight), Vec3f(partitionX + kStud, depth - kStud, z1), 0.4f, kBrickHeight,
         BuildMaterial::Masonry, holes);
    w.part("furniture", kBuildFilterDetail);
    const float floorTop = z0 + kPlateHeight;
    const int roomA = int(std::lround((partitionX - kStud) / kStud)), roomB = int(std::lround((width - kStud - partitionX - kStud) / kStud));
    const int rows = int(std::lround((depth - 2.f * kStud) / kStud));
    FurniturePlacer a(kStud, kStud, roomA, rows, floorTop);
    a.furnish(w, rng, std::max(1, roomA * rows / 8));
    FurniturePlacer b(partitionX + kStud, kStud, roomB, rows, floorTop);
    b.furnish(w, rng, std::max(1, roomB * rows / 8));
  }
  const float top = float(storeys) * storeyH;
  w.part("ceiling");
  tile(w, Vec3f(0, 0, top), Vec3f(width, depth, top + kPlateHeight), Vec3f(0.8f, kStud, kPlateHeight), BuildMaterial::Wood);
  w.part("roof");
  hipRoof(w, 0.f, width, 0.f, depth, top + kPlateHeight, kStud, kBrickHeight * 0.5f, BuildMaterial::Masonry);
  // Porch: two pillars in front of the door holding a plate roof against the wall.
  w.part("porch");
  const float porchH = 6.f * kBrickHeight;
  for (float dx : {-1.f, 1.f}) w.addPillar(Vec3f(doorX + dx * 1.f, -0.8f, 0.f), 0.2f, porchH, BuildMaterial::Concrete);
  tile(w, Vec3f(doorX - 1.6f, -1.6f, porchH), Vec3f(doorX + 1.6f, 0.f, porchH + kPlateHeight), Vec3f(0.8f, 0.8f, kPlateHeight),
       BuildMaterial::Wood);
}

// ---------------------------------------------------------------------------------- truck

void truckBody(BuildWriter& w, uint64_t seed, float scale) {
  SeededRandom rng(seed);
  const float s = std::sqrt(scale);
  const float length = snap(12.f * s, 0.8f, 4.8f), width = snap(3.2f * s, 0.8f, 2.4f);
  const float cabLength = snap(length * (0.28f + 0.04f * float(rng.unit())), 0.8f, 1.6f);
  const float hw = width * 0.5f;
  const float radius = std::max(0.32f, 0.56f * s), wheelWidth = std::max(0.24f, 0.48f * s);
  const float axleR = 0.12f;
  const float railZ0 = radius + axleR, railZ1 = railZ0 + kBrickHeight;
  const float deckTop = railZ1 + 3.f * kPlateHeight;
  const float bedEnd = length - cabLength;  // bed is x in [0, bedEnd], the cab in front of it

  w.part("chassis");
  for (float side : {-1.f, 1.f}) {
    const float y0 = side < 0 ? -hw + kStud : hw - 2.f * kStud;
    tile(w, Vec3f(0, y0, railZ0), Vec3f(length, y0 + kStud, railZ1), Vec3f(0.8f, kStud, kBrickHeight), BuildMaterial::Metal);
  }
  tile(w, Vec3f(0, -hw, railZ1), Vec3f(length, hw, deckTop), Vec3f(kStud, kStud, kPlateHeight), BuildMaterial::Metal);
  // Bumper and fuel tank (a cylinder along X between the rails).
  tile(w, Vec3f(length, -hw, railZ0), Vec3f(length + kStud, hw, railZ1), Vec3f(kStud, 0.8f, kBrickHeight / 2.f), BuildMaterial::Metal);
  const float tankR = std::min(kBrickHeight * 0.5f, hw - 2.f * kStud);
  w.add(Vec3f(length * 0.45f, 0.f, railZ0 + tankR), Vec3f(length * 0.12f, tankR, tankR), BuildMaterial::Metal,
        BrickShape::Cylinder, rotation(kPosX, 0), 16);

  w.part("wheels");
  const float hubcap = radius * (0.4f + 0.2f * float(rng.unit()));
  const std::array<float, 3> axles = {length * 0.14f, length * 0.14f + 2.2f * radius, length - cabLength * 0.5f};
  for (float ax : axles) {
    // Axle under the rails, along Y; wheels outside the body, their axis along Y too.
    w.add(Vec3f(ax, 0.f, radius), Vec3f(axleR, hw, axleR), BuildMaterial::Metal, BrickShape::Cylinder, rotation(kPosY, 0), 12);
    for (float side : {-1.f, 1.f}) {
      const AxisRotation out = rotation(side > 0 ? kPosY : kNegY, 0);
      const float yc = side * (hw + wheelWidth * 0.5f);
      w.add(Vec3f(ax, yc, radius), Vec3f(radius, wheelWidth * 0.5f, radius), BuildMaterial::Rubber, BrickShape::Cylinder, out, 24);
      w.add(Vec3f(ax, side * (hw + wheelWidth + 0.02f), radius), Vec3f(hubcap, 0.02f, hubcap), BuildMaterial::Metal,
            BrickShape::Cylinder, out, 16);
    }
  }

  w.part("cab");
  const float cabH = snap(2.4f * s, kBrickHeight, 3.f * kBrickHeight);
  std::vector<Aabb> holes;
  holes.reserve(16);
  const Vec3f cabLo(bedEnd, -hw, deckTop), cabHi(length, hw, deckTop + cabH);
  const float winZ0 = deckTop + cabH * 0.45f, winZ1 = deckTop + cabH - kPlateHeight;
  // Back wall (solid: it is also the bed's front wall), front wall with the windshield, sides with windows.
  wall(w, cabLo, Vec3f(bedEnd + kStud, hw, cabHi.z()), 0.2f, kPlateHeight, BuildMaterial::Metal);
  holes.push_back(Aabb{Vec3f(length - kStud - 0.1f, -hw + 2.f * kStud, winZ0), Vec3f(length + 0.1f, hw - 2.f * kStud, winZ1)});
  wall(w, Vec3f(length - kStud, -hw, deckTop), cabHi, 0.2f, kPlateHeight, BuildMaterial::Metal, holes);
  for (float side : {-1.f, 1.f}) {
    const float y0 = side < 0 ? -hw : hw - kStud;
    holes.clear();
    holes.push_back(Aabb{Vec3f(bedEnd + 2.f * kStud, y0 - 0.1f, winZ0), Vec3f(length - 2.f * kStud, y0 + kStud + 0.1f, winZ1)});
    wall(w, Vec3f(bedEnd + kStud, y0, deckTop), Vec3f(length - kStud, y0 + kStud, cabHi.z()), 0.2f, kPlateHeight,
         BuildMaterial::Metal, holes);
  }
  tile(w, Vec3f(bedEnd, -hw, cabHi.z()), Vec3f(length, hw, cabHi.z() + kPlateHeight), Vec3f(kStud, kStud, kPlateHeight),
       BuildMaterial::Metal);
  // Wind fairing on the roof: a row of wedges rising toward the back, corner wedges at its ends.
  const float fairZ = cabHi.z() + kPlateHeight;
  const int fairCells = int(std::lround(width / kStud));
  for (int j = 0; j < fairCells; ++j) {
    const Vec3f c(bedEnd + 0.6f, -hw + (float(j) + 0.5f) * kStud, fairZ + kBrickHeight * 0.5f);
    const Vec3f half(0.6f, kStud * 0.5f, kBrickHeight * 0.5f);
    if (j == 0) w.add(c, half, BuildMaterial::Metal, BrickShape::CornerWedge, rotation(kPosZ, 3));
    else if (j == fairCells - 1) w.add(c, half, BuildMaterial::Metal, BrickShape::CornerWedge, rotation(kPosZ, 0));
    else w.add(c, half, BuildMaterial::Metal, BrickShape::Wedge, rotation(kPosZ, 0));
  }
  // Headlights (cylinders facing +X) and an exhaust stack beside the cab, on either side.
  const float exhaustSide = rng.below(2) == 0 ? -1.f : 1.f;
  for (float side : {-1.f, 1.f})
    w.add(Vec3f(length + 0.04f, side * (hw - 0.4f), deckTop + 0.3f), Vec3f(0.04f, 0.16f, 0.16f), BuildMaterial::Glass,
          BrickShape::Cylinder, rotation(kPosX, 0), 12);
  // Radiator grille of microbricks on the cab's front, between the headlights.
  tile(w, Vec3f(length, -hw + 0.8f, deckTop), Vec3f(length + kMicro, hw - 0.8f, deckTop + cabH * 0.4f),
       Vec3f(kMicro, kMicro, kMicro), BuildMaterial::Metal);
  for (int k = 0; k < int(std::lround(cabH / kBrickHeight)) + 1; ++k)
    w.addPillar(Vec3f(bedEnd + 0.4f, exhaustSide * (hw + 0.1f), deckTop + float(k) * kBrickHeight), 0.08f, kBrickHeight,
                BuildMaterial::Metal, 8);

  w.part("cab_interior", kBuildFilterDetail);
  const float cabInX0 = bedEnd + kStud, cabInX1 = length - kStud;
  // Seats: a brick base, a plate, a backrest, across the cab.
  const int seats = std::max(1, int((width - 2.f * kStud) / 0.8f));
  for (int k = 0; k < seats; ++k) {
    const Vec3f o(cabInX0, -hw + kStud + float(k) * 0.8f, deckTop);
    tile(w, o, o + Vec3f(0.8f, 0.8f, kBrickHeight), Vec3f(kStud, kStud, kBrickHeight), BuildMaterial::Plastic);
    tile(w, o + Vec3f(0, 0, kBrickHeight), o + Vec3f(0.8f, 0.8f, kBrickHeight + kPlateHeight), Vec3f(kStud, kStud, kPlateHeight),
         BuildMaterial::Plastic);
    w.addBox(o + Vec3f(0, 0, kBrickHeight + kPlateHeight), o + Vec3f(kMicro * 2.f, 0.8f, 2.f * kBrickHeight + kPlateHeight),
             BuildMaterial::Plastic);
  }
  // Dashboard along the windshield, and a steering wheel facing the driver (axis along -X).
  if (cabInX1 - cabInX0 >= 1.6f) {
    tile(w, Vec3f(cabInX1 - kStud, -hw + kStud, deckTop), Vec3f(cabInX1, hw - kStud, deckTop + 2.f * kBrickHeight),
         Vec3f(kStud, kStud, kPlateHeight), BuildMaterial::Plastic);
    w.add(Vec3f(cabInX1 - kStud - 0.04f, -hw + kStud + 0.4f, deckTop + 2.f * kBrickHeight), Vec3f(0.04f, 0.2f, 0.2f),
          BuildMaterial::Plastic, BrickShape::Cylinder, rotation(kNegX, 1), 16);
  }

  w.part("bed");
  const float bedWallH = snap(1.44f * s, kPlateHeight, 3.f * kPlateHeight);
  for (float side : {-1.f, 1.f}) {
    const float y0 = side < 0 ? -hw : hw - kStud;
    wall(w, Vec3f(0, y0, deckTop), Vec3f(bedEnd, y0 + kStud, deckTop + bedWallH), kStud, kPlateHeight, BuildMaterial::Wood);
    // Tie-down rail on top of each side wall.
    tile(w, Vec3f(0, y0, deckTop + bedWallH), Vec3f(bedEnd, y0 + kStud, deckTop + bedWallH + kPlateHeight),
         Vec3f(1.6f, kStud, kPlateHeight), BuildMaterial::Metal);
  }
  wall(w, Vec3f(0, -hw + kStud, deckTop), Vec3f(kStud, hw - kStud, deckTop + bedWallH), kStud, kPlateHeight, BuildMaterial::Wood);
  // Floor boards on the deck inside the bed (microplates, so cargo has a detailed surface).
  const Vec3f bedLo(kStud, -hw + kStud, deckTop), bedHi(bedEnd, hw - kStud, deckTop + kMicro);
  tile(w, bedLo, bedHi, Vec3f(kStud, 0.2f, kMicro), BuildMaterial::Wood);
  w.interior(Aabb{Vec3f(bedLo.x(), bedLo.y(), bedHi.z()), Vec3f(bedHi.x(), bedHi.y(), deckTop + bedWallH + 2.f)});
}

// ---------------------------------------------------------------------------------- carrier

// A small parked aircraft on a deck at z: fuselage boxes along X, wedge wings, a corner-wedge tail.
void aircraft(BuildWriter& w, SeededRandom& rng, const Vec3f& o) {
  const float body = 0.8f;
  const int wingChord = 2 + int(rng.below(3));  // 2..4 wedges from front to back
  tile(w, o + Vec3f(0, -body * 0.5f, 0), o + Vec3f(6.4f, body * 0.5f, body), Vec3f(0.8f, body, body), BuildMaterial::Metal);
  w.add(o + Vec3f(6.4f + 0.4f, 0, body * 0.5f), Vec3f(0.4f, body * 0.5f, body * 0.5f), BuildMaterial::Glass, BrickShape::Wedge,
        rotation(kPosZ, 0));
  for (float side : {-1.f, 1.f}) {
    for (int k = 0; k < wingChord; ++k) {
      const Vec3f c = o + Vec3f(1.6f + float(k) * 0.8f, side * (body * 0.5f + 1.2f), body * 0.5f);
      w.add(c, Vec3f(0.4f, 1.2f, 0.08f), BuildMaterial::Metal, BrickShape::Wedge, rotation(kPosZ, 0));
    }
  }
  w.add(o + Vec3f(0.4f, 0, body + 0.4f), Vec3f(0.4f, 0.4f, 0.4f), BuildMaterial::Metal, BrickShape::CornerWedge, rotation(kPosZ, 0));
}

void carrierBody(BuildWriter& w, uint64_t seed, float scale) {
  SeededRandom rng(seed);
  const float s = std::sqrt(scale);
  const float shell = 0.8f;                       // hull plating thickness
  const float hull = snap(240.f * s, 3.2f, 48.f);  // length of the straight hull (bow beyond it)
  const float beam = snap(32.f * s, 1.6f, 6.4f);
  const float rowH = 0.96f;
  const int lowerRows = std::max(2, int(std::lround(8.f * s / rowH)));
  const int hangarRows = std::max(3, int(std::lround(8.f * s / rowH)));
  const float hangarDeck = shell + float(lowerRows) * rowH;        // bottom of the hangar floor plates
  const float hangarFloor = hangarDeck + rowH;                      // top of the hangar floor
  const float flightDeck = hangarFloor + float(hangarRows) * rowH;  // bottom of the flight deck
  // note: every level is a whole number of rows, so the side walls end exactly at the flight deck.
  const int bowRows = lowerRows + 1 + hangarRows;
  const float run = 1.6f;
  const float innerY0 = shell, innerY1 = beam - shell;

  // Hangar in the middle half of the hull; the large opening is in the starboard (high Y) side.
  const float hx0 = snap(hull * 0.25f, 1.6f, 3.2f), hx1 = snap(hull * 0.75f, 1.6f, hx0 + 6.4f);
  const float openingHalf = snap((hx1 - hx0) * 0.2f, 1.6f, 1.6f), openingX = snap((hx0 + hx1) * 0.5f, 1.6f, 0.f);
  const Aabb opening{Vec3f(openingX - openingHalf, innerY1 - 0.1f, hangarFloor), Vec3f(openingX + openingHalf, beam + 0.1f, flightDeck - rowH)};

  w.part("hull");
  tile(w, Vec3f(0, 0, 0), Vec3f(hull, beam, shell), Vec3f(1.6f, 1.6f, shell), BuildMaterial::Metal);
  for (int k = 0; k < bowRows; ++k) {
    // Each row reaches one run further forward than the row below: a raked bow, closed by
    // wedges facing forward and down (direction -Z flips the canonical ramp upside down).
    const float z0 = shell + float(k) * rowH, z1 = z0 + rowH;
    const float xEnd = hull + float(k) * run;
    wall(w, Vec3f(0, 0, z0), Vec3f(xEnd, shell, z1), 3.2f, rowH, BuildMaterial::Metal);
    wall(w, Vec3f(0, innerY1, z0), Vec3f(xEnd, beam, z1), 3.2f, rowH, BuildMaterial::Metal, std::span<const Aabb>(&opening, 1));
    const int seg = std::max(1, int(std::lround(beam / 3.2f)));
    const float ys = beam / float(seg);
    for (int j = 0; j < seg; ++j)
      w.add(Vec3f(xEnd + run * 0.5f, (float(j) + 0.5f) * ys, (z0 + z1) * 0.5f), Vec3f(run * 0.5f, ys * 0.5f, rowH * 0.5f),
            BuildMaterial::Metal, BrickShape::Wedge, rotation(kNegZ, 0));
  }
  // Stern wall.
  wall(w, Vec3f(0, innerY0, shell), Vec3f(shell, innerY1, flightDeck), 3.2f, rowH, BuildMaterial::Metal);

  w.part("decks");
  tile(w, Vec3f(shell, innerY0, hangarDeck), Vec3f(hull, innerY1, hangarFloor), Vec3f(0.8f, 0.8f, rowH), BuildMaterial::Metal);
  const float midDeck = shell + float(lowerRows / 2) * rowH;
  if (lowerRows >= 4)
    tile(w, Vec3f(shell, innerY0, midDeck), Vec3f(hull, innerY1, midDeck + kPlateHeight), Vec3f(0.8f, 0.8f, kPlateHeight),
         BuildMaterial::Metal);
  // Watertight bulkheads in the lower hull every ~24 units, split around the mid deck.
  w.part("bulkheads");
  const float bulkheadPitch = std::max(12.f, snap(24.f * s, 1.6f, 1.6f));
  for (float x0 = bulkheadPitch; x0 + 2.f * shell < hull; x0 += bulkheadPitch) {
    if (lowerRows >= 4) {
      wall(w, Vec3f(x0, innerY0, shell), Vec3f(x0 + shell, innerY1, midDeck), 1.6f, rowH / 2, BuildMaterial::Metal);
      wall(w, Vec3f(x0, innerY0, midDeck + kPlateHeight), Vec3f(x0 + shell, innerY1, hangarDeck), 1.6f, rowH / 2, BuildMaterial::Metal);
    } else {
      wall(w, Vec3f(x0, innerY0, shell), Vec3f(x0 + shell, innerY1, hangarDeck), 1.6f, rowH / 2, BuildMaterial::Metal);
    }
  }
  w.part("hangar");
  // The hangar's end walls; its sides are the hull, its ceiling the flight deck.
  wall(w, Vec3f(hx0 - shell, innerY0, hangarFloor), Vec3f(hx0, innerY1, flightDeck), 1.6f, rowH, BuildMaterial::Metal);
  wall(w, Vec3f(hx1, innerY0, hangarFloor), Vec3f(hx1 + shell, innerY1, flightDeck), 1.6f, rowH, BuildMaterial::Metal);
  w.interior(Aabb{Vec3f(hx0, innerY0, hangarFloor), Vec3f(hx1, innerY1, flightDeck)});

  w.part("flight_deck");
  const float deckTop = flightDeck + shell;
  const float deckEnd = hull + float(bowRows) * run;
  tile(w, Vec3f(0, 0, flightDeck), Vec3f(deckEnd, beam, deckTop), Vec3f(0.8f, 0.8f, shell), BuildMaterial::Metal);
  // Angled-deck sponson to port, over the sea.
  const float sponson = snap(beam * 0.2f, 1.6f, 1.6f);
  tile(w, Vec3f(hx0, -sponson, flightDeck), Vec3f(hx1, 0, deckTop), Vec3f(1.6f, 1.6f, shell), BuildMaterial::Metal);
  w.part("deck_markings", kBuildFilterDetail);
  // Edge line along the port side, clear of the wires and the parked aircraft.
  for (float x = 3.2f; x + 2.4f < deckEnd; x += 4.8f)
    w.addBox(Vec3f(x, 0.4f, deckTop), Vec3f(x + 2.4f, 0.8f, deckTop + kMicro), BuildMaterial::Plastic);
  const int wires = 3 + int(rng.below(2));
  for (int k = 0; k < wires; ++k) {
    const float x = 3.2f + float(k) * 1.6f;
    w.add(Vec3f(x, beam * 0.5f, deckTop + 0.04f), Vec3f(0.04f, beam * 0.35f, 0.04f), BuildMaterial::Metal, BrickShape::Cylinder,
          rotation(kPosY, 0), 8);
  }

  w.part("island");
  const float ix0 = snap(hull * (0.55f + 0.1f * float(rng.unit())), 1.6f, 1.6f), ix1 = ix0 + snap(24.f * s, 1.6f, 4.8f);
  const float iy1 = beam, iy0 = beam - snap(8.f * s, 1.6f, 3.2f);
  std::vector<Aabb> holes;
  holes.reserve(64);
  const int islandLevels = std::max(2, int(std::lround(5.f * s)));
  const float levelH = 6.f * kBrickHeight;
  for (int level = 0; level < islandLevels; ++level) {
    const float z0 = deckTop + float(level) * levelH;
    perimeterWalls(w, holes, ix0, ix1, iy0, iy1, z0, z0 + levelH, 1.6f, kBrickHeight, BuildMaterial::Metal, 2.4f, z0 + 1.f,
                   z0 + 2.4f, std::nullopt);
    tile(w, Vec3f(ix0 + kStud, iy0 + kStud, z0 + levelH - kPlateHeight), Vec3f(ix1 - kStud, iy1 - kStud, z0 + levelH),
         Vec3f(1.6f, 1.6f, kPlateHeight), BuildMaterial::Metal);
  }
  const float islandTop = deckTop + float(islandLevels) * levelH;
  tile(w, Vec3f(ix0, iy0, islandTop), Vec3f(ix1, iy1, islandTop + kPlateHeight), Vec3f(1.6f, 1.6f, kPlateHeight), BuildMaterial::Metal);
  // Mast of stacked cylinders and a radar disc on top.
  const Vec3f mast((ix0 + ix1) * 0.5f, (iy0 + iy1) * 0.5f, islandTop + kPlateHeight);
  const int mastSegs = std::max(3, int(std::lround(12.f * s)));
  for (int k = 0; k < mastSegs; ++k) w.addPillar(mast + Vec3f(0, 0, float(k)), 0.4f, 1.f, BuildMaterial::Metal);
  const float radar = 1.2f + 0.8f * float(rng.unit());
  w.addPillar(mast + Vec3f(0, 0, float(mastSegs)), radar, kPlateHeight, BuildMaterial::Metal, 32);

  w.part("aircraft", kBuildFilterDetail);
  const int planes = std::max(1, int(std::lround(40.f * scale)));
  // Parked in rows (each aircraft is 7.2 long and 5.6 wide) between the wires and the island,
  // then ahead of the island; the seed picks which rows start.
  int placed = 0;
  const float firstX = 12.8f + 1.6f * float(rng.below(3));
  for (float x = firstX; x + 8.f < ix0 && placed < planes; x += 8.f)
    for (float y = 2.f; y + 5.6f < beam && placed < planes; y += 6.4f, ++placed) aircraft(w, rng, Vec3f(x, y + 2.8f, deckTop));
  for (float x = ix1 + 1.6f; x + 8.f < deckEnd && placed < planes; x += 8.f)
    for (float y = 2.f; y + 5.6f < beam && placed < planes; y += 6.4f, ++placed) aircraft(w, rng, Vec3f(x, y + 2.8f, deckTop));
}

// ---------------------------------------------------------------------------------- ring station

// Which way is "up" (toward the axis) for a cell of the pixelated ring at (x, y).
AxisRotation towardAxis(float x, float y, int spin) {
  const int direction = std::abs(x) >= std::abs(y) ? (x > 0.f ? kNegX : kPosX) : (y > 0.f ? kNegY : kPosY);
  return rotation(direction, spin);
}

void ringBody(BuildWriter& w, uint64_t seed, float scale) {
  const float s = std::sqrt(scale);
  const float c = kStud;  // lattice cell in the XY plane
  // note: shells 1.5 cells thick keep the digital circle closed: a 1-cell ring leaves
  // diagonal-only contacts a small body could slip through.
  const float band = 1.5f * c;
  const float floorR = snap(80.f * s, c, 8.f);
  const float innerR = floorR - snap(8.f * s, c, 2.4f) - band;
  const float width = snap(16.f * s, 1.6f, 3.2f);
  const float seg = 0.8f;  // length along Z of floor and ceiling bricks
  const int zSegs = std::max(1, int(std::lround(width / seg)));
  const float zStep = width / float(zSegs), z0 = -width * 0.5f;
  const int hubCells = std::max(2, int(std::lround(4.f * s / c)));
  const float hubR = float(hubCells) * c;
  const int spokeHalf = 2;  // spokes are 2 * spokeHalf cells wide and tall
  w.ring({innerR, floorR, width});

  const float outerR = floorR + band;
  const int n = int(std::ceil(outerR / c)) + 1;
  // Squared radii: classification uses exact float products only, so it is the same everywhere.
  const float floor2 = floorR * floorR, outer2 = outerR * outerR, inner2 = innerR * innerR,
              ceilOut = innerR + band, ceilOut2 = ceilOut * ceilOut;
  const float maxModule = floorR - ceilOut - 2.f * c;
  auto cellCenter = [&](int i, int j) { return Vec3f((float(i) + 0.5f) * c, (float(j) + 0.5f) * c, 0.f); };

  w.part("floor");
  for (int j = -n; j < n; ++j)
    for (int i = -n; i < n; ++i) {
      const Vec3f p = cellCenter(i, j);
      const float d2 = p.x() * p.x() + p.y() * p.y();
      if (d2 < floor2 || d2 >= outer2) continue;
      const AxisRotation up = towardAxis(p.x(), p.y(), (i + j) & 3);
      for (int k = 0; k < zSegs; ++k)
        w.add(Vec3f(p.x(), p.y(), z0 + (float(k) + 0.5f) * zStep), Vec3f(c * 0.5f, c * 0.5f, zStep * 0.5f),
              BuildMaterial::Concrete, BrickShape::Box, up);
    }
  w.part("ceiling");
  for (int j = -n; j < n; ++j)
    for (int i = -n; i < n; ++i) {
      const Vec3f p = cellCenter(i, j);
      const float d2 = p.x() * p.x() + p.y() * p.y();
      if (d2 < inner2 || d2 >= ceilOut2) continue;
      const AxisRotation down = towardAxis(-p.x(), -p.y(), (i - j) & 3);
      // Skylight strips of glass in the middle of the band, every 16 cells around the ring.
      const bool skylightColumn = (std::abs(i) % 16) < 2 || (std::abs(j) % 16) < 2;
      for (int k = 0; k < zSegs; ++k) {
        const bool glass = skylightColumn && k > 1 && k + 2 < zSegs;
        w.add(Vec3f(p.x(), p.y(), z0 + (float(k) + 0.5f) * zStep), Vec3f(c * 0.5f, c * 0.5f, zStep * 0.5f),
              glass ? BuildMaterial::Glass : BuildMaterial::Metal, BrickShape::Box, down);
      }
    }
  w.part("walls");
  // Side walls close the band at both ends of Z, on a coarser 0.8 lattice (they are plain plates).
  const float wc = 2.f * c;
  const int wn = n / 2 + 1;
  for (float side : {-1.f, 1.f})
    for (int j = -wn; j < wn; ++j)
      for (int i = -wn; i < wn; ++i) {
        const float x = (float(i) + 0.5f) * wc, y = (float(j) + 0.5f) * wc;
        const float d2 = x * x + y * y;
        if (d2 < inner2 || d2 >= outer2) continue;
        w.add(Vec3f(x, y, side * (width * 0.5f + c * 0.5f)), Vec3f(wc * 0.5f, wc * 0.5f, c * 0.5f), BuildMaterial::Metal);
      }
  w.part("modules", kBuildFilterDetail);
  // Modules (rooms, tanks, crates) standing on the floor: solid blocks of cells in the band just
  // inside the floor. The XY plane is cut into 16-cell blocks; a hash of (seed, block) decides
  // whether a block has a module, how tall it is and which Z range it covers.
  if (maxModule >= c) {
    for (int j = -n; j < n; ++j)
      for (int i = -n; i < n; ++i) {
        const Vec3f p = cellCenter(i, j);
        const float d2 = p.x() * p.x() + p.y() * p.y();
        if (d2 >= floor2) continue;
        const int bx = i >> 4, by = j >> 4;  // arithmetic shift: floor division for negatives too
        SeededRandom blockRng(seed ^ (uint64_t(uint32_t(bx)) * 0x9E3779B1ull) ^ (uint64_t(uint32_t(by)) << 32));
        if (blockRng.below(3) == 0) continue;
        const float height = std::min(maxModule, c * float(3 + blockRng.below(6)));
        const float inner = floorR - height;
        if (d2 < inner * inner) continue;
        const int kz0 = int(blockRng.below(uint32_t(zSegs))), kz1 = std::min(zSegs, kz0 + 1 + int(blockRng.below(3)));
        const AxisRotation up = towardAxis(p.x(), p.y(), 0);
        for (int k = kz0; k < kz1; ++k)
          w.add(Vec3f(p.x(), p.y(), z0 + (float(k) + 0.5f) * zStep), Vec3f(c * 0.5f, c * 0.5f, zStep * 0.5f),
                BuildMaterial::Plastic, BrickShape::Box, up);
      }
  }
  w.part("hub");
  for (int k = 0; k < zSegs; ++k)
    w.add(Vec3f(0, 0, z0 + (float(k) + 0.5f) * zStep), Vec3f(hubR, hubR, zStep * 0.5f), BuildMaterial::Metal,
          BrickShape::Cylinder, AxisRotation::identity(), 32);
  w.part("spokes");
  // Four spokes along +-X and +-Y from the hub to the ceiling, square tubes of cells.
  for (int axis = 0; axis < 2; ++axis)
    for (int u = -n; u < n; ++u) {
      if (u >= -hubCells && u < hubCells) continue;
      for (int v = -spokeHalf; v < spokeHalf; ++v) {
        const Vec3f p = axis == 0 ? cellCenter(u, v) : cellCenter(v, u);
        const float d2 = p.x() * p.x() + p.y() * p.y();
        if (d2 >= inner2) continue;
        for (int k = -spokeHalf; k < spokeHalf; ++k) {
          const bool shell = v == -spokeHalf || v == spokeHalf - 1 || k == -spokeHalf || k == spokeHalf - 1;
          if (!shell) continue;  // hollow: a corridor runs inside
          w.add(Vec3f(p.x(), p.y(), (float(k) + 0.5f) * c), Vec3f::Constant(c * 0.5f), BuildMaterial::Metal, BrickShape::Box,
                rotation(axis == 0 ? kPosX : kPosY, (u & 1) * 2));
        }
      }
    }
}

// ---------------------------------------------------------------------------------- plate stack

void plateStackBody(BuildWriter& w, uint64_t seed, float scale) {
  SeededRandom rng(seed);
  const int plates = std::max(3, int(std::lround(300.f * scale)));
  w.part("plates");
  for (int p = 0; p < plates; ++p) {
    // Mostly 64 x 64, a third 64 x 48 turned either way; offsets of up to 4 studs each way.
    const bool narrow = rng.below(3) == 0;
    const int spin = int(rng.below(4));
    const float across = narrow ? 24.f : 32.f;
    const Vec3f half = (spin & 1) ? Vec3f(across, 32.f, kPlateHeight * 0.5f) : Vec3f(32.f, across, kPlateHeight * 0.5f);
    const float dx = float(int(rng.below(9)) - 4) * kStud, dy = float(int(rng.below(9)) - 4) * kStud;
    w.add(Vec3f(dx, dy, (float(p) + 0.5f) * kPlateHeight), half, BuildMaterial::Plastic, BrickShape::Box, rotation(kPosZ, spin));
  }
}

// ---------------------------------------------------------------------------------- city block

// One city building on [x0, x1] x [y0, y1]: storeys of floor plates and running-bond walls with
// windows, a front door, lobby pillars, and a hip roof or a flat roof with a parapet and a tank.
void cityBuilding(BuildWriter& w, SeededRandom& rng, std::vector<Aabb>& holes, float x0, float x1, float y0, float y1,
                  int storeys) {
  const float storeyH = 8.f * kBrickHeight;
  for (int st = 0; st < storeys; ++st) {
    const float z0 = float(st) * storeyH;
    tile(w, Vec3f(x0 + kStud, y0 + kStud, z0), Vec3f(x1 - kStud, y1 - kStud, z0 + kPlateHeight), Vec3f(1.6f, 1.6f, kPlateHeight),
         BuildMaterial::Concrete);
    std::optional<Aabb> door;
    const float doorX = snap((x0 + x1) * 0.5f, 0.8f, 0.f);
    if (st == 0) door = Aabb{Vec3f(doorX - 1.2f, y0 - 0.1f, z0 + kPlateHeight), Vec3f(doorX + 1.2f, y0 + kStud + 0.1f, z0 + 2.88f)};
    perimeterWalls(w, holes, x0, x1, y0, y1, z0, z0 + storeyH, 0.8f, kBrickHeight, BuildMaterial::Masonry, 1.6f, z0 + 1.f,
                   z0 + 2.9f, door);
    if (st == 0) {
      for (float x = x0 + 3.2f; x < x1 - 2.4f; x += 4.8f)
        for (float y = y0 + 3.2f; y < y1 - 2.4f; y += 4.8f)
          w.addPillar(Vec3f(x, y, z0 + kPlateHeight), 0.2f, storeyH - kPlateHeight, BuildMaterial::Concrete);
    }
  }
  const float top = float(storeys) * storeyH;
  tile(w, Vec3f(x0, y0, top), Vec3f(x1, y1, top + kPlateHeight), Vec3f(1.6f, 1.6f, kPlateHeight), BuildMaterial::Concrete);
  const float roofZ = top + kPlateHeight;
  if (rng.below(2) == 0) {
    hipRoof(w, x0, x1, y0, y1, roofZ, 1.6f, kBrickHeight, BuildMaterial::Masonry);
    return;
  }
  holes.clear();
  perimeterWalls(w, holes, x0, x1, y0, y1, roofZ, roofZ + kBrickHeight, 1.6f, kBrickHeight, BuildMaterial::Masonry, 1e9f, 0.f,
                 0.f, std::nullopt);
  const Vec3f tank((x0 + x1) * 0.5f, (y0 + y1) * 0.5f, roofZ);
  for (int k = 0; k < 4; ++k) w.addPillar(tank + Vec3f(0, 0, float(k) * 0.8f), 1.2f, 0.8f, BuildMaterial::Metal, 24);
  for (float dx : {-1.f, 1.f}) {
    const Vec3f unit(tank.x() + dx * 4.f, tank.y(), roofZ);
    w.addBox(unit - Vec3f(0.4f, 0.4f, 0.f), unit + Vec3f(0.4f, 0.4f, kBrickHeight), BuildMaterial::Metal);
  }
}

void cityBody(BuildWriter& w, uint64_t seed, float scale) {
  SeededRandom rng(seed);
  const int lots = std::max(1, int(std::lround(190.f * scale)));
  const int ramps = std::max(1, int(std::lround(8.f * scale)));
  const int patches = std::max(8, int(std::lround(375.f * scale)));
  const float pitch = 40.f, lotSize = 32.f;  // streets are the 8 units between lots
  const int nx = int(std::ceil(std::sqrt(double(lots))));
  const int ny = (lots + nx - 1) / nx;
  const float rampLength = 500.f, rampSlot = 520.f, laneWidth = 16.f;
  const int rampsPerLane = std::max(1, int(float(nx) * pitch / rampSlot));
  const int lanes = (ramps + rampsPerLane - 1) / rampsPerLane;
  const int patchesPerRamp = (patches + ramps - 1) / ramps;
  const int patchRows = (patchesPerRamp + 199) / 200;  // 200 patches of 2.4 fit along one ramp
  if (patchRows > 3) throw InvalidInput("generateCityBlock: scale gives too many microbrick patches per ramp");

  const float xMax = std::ceil(std::max(float(nx) * pitch, float(rampsPerLane) * rampSlot) / 32.f) * 32.f;
  const float yMin = -std::ceil(float(lanes) * laneWidth / 32.f) * 32.f, yMax = std::ceil(float(ny) * pitch / 32.f) * 32.f;
  w.part("streets");
  tile(w, Vec3f(0, yMin, -kPlateHeight), Vec3f(xMax, yMax, 0.f), Vec3f(32.f, 32.f, kPlateHeight), BuildMaterial::Asphalt);

  w.part("buildings");
  std::vector<Aabb> holes;
  holes.reserve(64);
  for (int l = 0; l < lots; ++l) {
    const float lx = float(l % nx) * pitch + 4.f, ly = float(l / nx) * pitch + 4.f;
    const float bx = 16.f + 3.2f * float(rng.below(6)), by = 16.f + 3.2f * float(rng.below(6));
    const int storeys = 3 + int(rng.below(12));
    const float ox = lx + snap((lotSize - bx) * 0.5f, 0.8f, 0.f), oy = ly + snap((lotSize - by) * 0.5f, 0.8f, 0.f);
    cityBuilding(w, rng, holes, ox, ox + bx, oy, oy + by, storeys);
  }

  auto rampOrigin = [&](int r) {
    const float x = float(r % rampsPerLane) * rampSlot + 10.f, y = yMin + float(r / rampsPerLane) * laneWidth + 1.f;
    return Vec3f(x, y, 0.f);  // ramp covers [x, x + 500] x [y, y + 8] x [0, 4]
  };
  w.part("ramps");
  for (int r = 0; r < ramps; ++r) {
    const Vec3f o = rampOrigin(r);
    const Vec3f half(rampLength * 0.5f, 4.f, 2.f);
    w.add(o + half, half, BuildMaterial::Concrete, BrickShape::Wedge, rotation(kPosZ, (r & 1) * 2));
  }
  w.part("microbricks", kBuildFilterDetail);
  // Patches of 20 x 20 microbrick columns, 1..3 high, in rows 0.8 from the ramp's side: the
  // article's mix of the largest and the smallest bricks side by side.
  for (int p = 0; p < patches; ++p) {
    const int r = p % ramps, slot = p / ramps;
    const Vec3f o = rampOrigin(r) + Vec3f(0.4f + float(slot % 200) * 2.4f, 8.8f + float(slot / 200) * 2.f, 0.f);
    for (int j = 0; j < 20; ++j)
      for (int i = 0; i < 20; ++i) {
        const int h = 1 + int(rng.below(3));
        for (int k = 0; k < h; ++k)
          w.add(o + Vec3f((float(i) + 0.5f) * kMicro, (float(j) + 0.5f) * kMicro, (float(k) + 0.5f) * kMicro),
                Vec3f::Constant(kMicro * 0.5f), BuildMaterial::Plastic);
      }
  }
}

void requireScale(float scale, double lo, double hi, const char* context) {
  // note: the float argument 0.04f is slightly below the double 0.04; the slack accepts it.
  requireInRange(double(scale), lo * (1.0 - 1e-6), hi, context, "scale");
}

}  // namespace

GeneratedBuild generateHouse(uint64_t seed, float scale) {
  requireScale(scale, 0.25, 64.0, "generateHouse");
  return runBuild("house", [&](BuildWriter& w) { houseBody(w, seed, scale); });
}

GeneratedBuild generateTruck(uint64_t seed, float scale) {
  requireScale(scale, 0.25, 64.0, "generateTruck");
  return runBuild("truck", [&](BuildWriter& w) { truckBody(w, seed, scale); });
}

GeneratedBuild generateCarrierShip(uint64_t seed, float scale) {
  requireScale(scale, 0.04, 64.0, "generateCarrierShip");
  return runBuild("carrier", [&](BuildWriter& w) { carrierBody(w, seed, scale); });
}

GeneratedBuild generateRingStation(uint64_t seed, float scale) {
  requireScale(scale, 0.01, 64.0, "generateRingStation");
  return runBuild("ring_station", [&](BuildWriter& w) { ringBody(w, seed, scale); });
}

GeneratedBuild generatePlateStackBricks(uint64_t seed, float scale) {
  requireScale(scale, 0.01, 64.0, "generatePlateStackBricks");
  return runBuild("plate_stack", [&](BuildWriter& w) { plateStackBody(w, seed, scale); });
}

GeneratedBuild generateCityBlock(uint64_t seed, float scale) {
  requireScale(scale, 0.001, 8.0, "generateCityBlock");
  return runBuild("city_block", [&](BuildWriter& w) { cityBody(w, seed, scale); });
}

std::vector<std::string> buildNames() { return {"house", "truck", "carrier", "ring_station", "plate_stack", "city_block"}; }

GeneratedBuild generateBuild(const std::string& name, uint64_t seed, float scale) {
  if (name == "house") return generateHouse(seed, scale);
  if (name == "truck") return generateTruck(seed, scale);
  if (name == "carrier") return generateCarrierShip(seed, scale);
  if (name == "ring_station") return generateRingStation(seed, scale);
  if (name == "plate_stack") return generatePlateStackBricks(seed, scale);
  if (name == "city_block") return generateCityBlock(seed, scale);
  std::string valid;
  for (const std::string& n : buildNames()) valid += (valid.empty() ? "" : ", ") + n;
  throw InvalidInput("generateBuild: name is \"" + name + "\", expected one of: " + valid);
}

}  // namespace bw
