// Seeded buildings: a furnished house, a stack of plates, and the city block of towers.
#include <algorithm>
#include <array>
#include <cmath>

#include "collision/content/build_writer.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"

namespace bw {

using namespace buildgen;

namespace {

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

// ---------------------------------------------------------------------------------- house

// Lamps on a room's ceiling at height z: one per ~8 x 8 units of floor [x0, x1] x [y0, y1], at
// the centres of an even grid (so they stay clear of the walls around the room).
void ceilingLamps(BuildWriter& w, float x0, float x1, float y0, float y1, float z) {
  const int nx = std::max(1, int(std::lround((x1 - x0) / 8.f))), ny = std::max(1, int(std::lround((y1 - y0) / 8.f)));
  const float cx = (x1 - x0) / float(nx), cy = (y1 - y0) / float(ny);
  const float radius = std::clamp(0.75f * std::max(cx, cy), 4.f, 15.f);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) w.light(Vec3f(x0 + (float(i) + 0.5f) * cx, y0 + (float(j) + 0.5f) * cy, z), radius);
}

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
    // Ceiling lamps 0.3 below the next floor, well above the tallest furniture (2.1 above the floor).
    ceilingLamps(w, kStud, partitionX, kStud, depth - kStud, z1 - 0.3f);
    ceilingLamps(w, partitionX + kStud, width - kStud, kStud, depth - kStud, z1 - 0.3f);
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
  // Porch lamp under the porch roof, between the pillars.
  w.light(Vec3f(doorX, -0.8f, porchH - 0.3f), 4.f);
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
      // The lobby lamp: in the middle of the pillar-grid cell nearest the centre (2.4 from the
      // pillars around it), 0.4 below the next floor.
      const float cellX = 4.8f * float(int((x1 - x0) * 0.5f / 4.8f)), cellY = 4.8f * float(int((y1 - y0) * 0.5f / 4.8f));
      w.light(Vec3f(x0 + 0.8f + cellX, y0 + 0.8f + cellY, z0 + storeyH - 0.4f),
              std::clamp(0.5f * std::max(x1 - x0, y1 - y0), 4.f, 15.f));
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

  // Street lamps 4.5 above the street centre lines (x = 40 i, y = 40 j; buildings keep 4 away
  // from them, the ramps and patches stay below y = 0 and 4 high) every 20 units.
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= 2 * nx; ++i) w.light(Vec3f(float(i) * pitch * 0.5f, float(j) * pitch, 4.5f), 10.f);
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j < ny; ++j) w.light(Vec3f(float(i) * pitch, (float(j) + 0.5f) * pitch, 4.5f), 10.f);

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

}  // namespace

GeneratedBuild generateHouse(uint64_t seed, float scale) {
  requireScale(scale, 0.25, 64.0, "generateHouse");
  return runBuild("house", [&](BuildWriter& w) { houseBody(w, seed, scale); });
}

GeneratedBuild generatePlateStackBricks(uint64_t seed, float scale) {
  requireScale(scale, 0.01, 64.0, "generatePlateStackBricks");
  return runBuild("plate_stack", [&](BuildWriter& w) { plateStackBody(w, seed, scale); });
}

GeneratedBuild generateCityBlock(uint64_t seed, float scale) {
  requireScale(scale, 0.001, 8.0, "generateCityBlock");
  return runBuild("city_block", [&](BuildWriter& w) { cityBody(w, seed, scale); });
}

}  // namespace bw
