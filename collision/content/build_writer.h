#pragma once
/// What the seeded build generators share (internal to collision/content/): brick dimensions,
/// the BuildWriter that collects bricks into parts (and the build's lights), and the building
/// blocks every generator uses (tiled boxes, running-bond walls, hip roofs, windows, perimeter
/// walls, points on a circle).
#include <optional>
#include <span>
#include <vector>

#include "collision/content/build_generators.h"

namespace bw::buildgen {

constexpr float kStud = 0.4f;          // side of a 1x1 brick
constexpr float kBrickHeight = 0.48f;  // height of a standard brick
constexpr float kPlateHeight = 0.16f;  // height of a plate
constexpr float kMicro = 0.08f;        // side of a microbrick

constexpr int kPosX = AxisRotation::PosX, kNegX = AxisRotation::NegX, kPosY = AxisRotation::PosY,
              kNegY = AxisRotation::NegY, kPosZ = AxisRotation::PosZ, kNegZ = AxisRotation::NegZ;

inline AxisRotation rotation(int direction, int spin) { return AxisRotation::fromDirectionSpin(direction, spin); }

// Rounds to a multiple of `step`, never below `minValue`: dimensions stay on the brick lattice.
inline float snap(float v, float step, float minValue) { return std::max(minValue, std::round(v / step) * step); }

inline bool strictlyInside(const Aabb& box, const Vec3f& p) {
  return (p.array() > box.min.array()).all() && (p.array() < box.max.array()).all();
}

// Collects bricks, or only counts them: every generator body runs twice (count, then write)
// so the output vector is allocated exactly once.
class BuildWriter {
 public:
  explicit BuildWriter(GeneratedBuild* out) : out_(out) {}

  uint32_t count() const { return count_; }
  uint32_t lightCount() const { return lightCount_; }

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
  // A light in open space; radius in our units.
  void light(const Vec3f& position, float radius, BuildLightKind kind = BuildLightKind::Point) {
    ++lightCount_;
    if (out_) out_->lights.push_back(BuildLight{position, radius, kind});
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
  uint32_t lightCount_ = 0;
  uint32_t filter_ = kBuildFilterStructure;
};


// Tiles the box [lo, hi] with boxes close to `cell` (stretched so that a whole number fits
// exactly), leaving out cells whose centre is strictly inside one of `holes`. With
// bondAxis >= 0 every other layer along Z is shifted by half a cell along that axis (running
// bond), so its first and last bricks are half bricks. Neighbours share their boundary values
// exactly, so the tiles touch without overlapping.
void tile(BuildWriter& w, const Vec3f& lo, const Vec3f& hi, const Vec3f& cell, BuildMaterial material,
          std::span<const Aabb> holes = {}, int bondAxis = -1);
// A wall one brick thick between lo and hi, bricks laid along its longer horizontal axis.
void wall(BuildWriter& w, const Vec3f& lo, const Vec3f& hi, float brickLength, float brickHeight,
          BuildMaterial material, std::span<const Aabb> holes = {});
// A hip roof over [x0, x1] x [y0, y1] starting at z0: level k is a ring of wedges (corner
// wedges at its four corners) inset by k slots, resting on a ring of boxes one slot further
// in, so the roof is a stepped shell one brick thick. Narrow tops are closed with boxes.
void hipRoof(BuildWriter& w, float x0, float x1, float y0, float y1, float z0, float slot, float rise,
             BuildMaterial material);
// Windows along a wall [lo, hi] every `pitch`, each `width` wide, spanning [z0, z1].
void addWindows(std::vector<Aabb>& holes, const Vec3f& lo, const Vec3f& hi, float pitch, float width, float z0,
                float z1);
// Four walls around [x0, x1] x [y0, y1] from z0 to z1, thickness one stud; the X-walls own the
// corners. Windows every `pitch` on every wall; `door` (if any) is also cut.
void perimeterWalls(BuildWriter& w, std::vector<Aabb>& holes, float x0, float x1, float y0, float y1, float z0, float z1,
                    float brickLength, float brickHeight, BuildMaterial material, float pitch, float winZ0, float winZ1,
                    const std::optional<Aabb>& door);
// Point k of n (n a positive multiple of 4) evenly spaced on the unit circle, counter-clockwise
// from +X: (cos, sin) of 2 pi k / n. Computed with + - * / only (quarter turns are exact, the
// rest a Taylor series on at most an eighth of a turn), so every platform gets the same bits.
Vec3f circlePoint(int k, int n);
// The bounds of the build's bricks.
void computeBounds(GeneratedBuild& b);
// Throws InvalidInput unless lo <= scale <= hi (a generator's accepted scales).
void requireScale(float scale, double lo, double hi, const char* context);

template <class Body>
GeneratedBuild runBuild(const char* name, Body&& body) {
  BuildWriter counter(nullptr);
  body(counter);
  GeneratedBuild out;
  out.name = name;
  out.bricks.reserve(counter.count());
  out.lights.reserve(counter.lightCount());
  BuildWriter writer(&out);
  body(writer);
  writer.finish();
  computeBounds(out);
  return out;
}

}  // namespace bw::buildgen
