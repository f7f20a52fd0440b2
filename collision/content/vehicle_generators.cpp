// Seeded vehicles: a truck with an open bed, and a carrier with a hangar and aircraft.
#include <algorithm>
#include <array>
#include <cmath>

#include "collision/content/build_writer.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"

namespace bw {

using namespace buildgen;

namespace {

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

  // Head lights 0.22 in front of the headlight bricks (which end 0.08 past the cab; the bumper
  // below reaches 0.4 but stops under the deck), tail lights 0.3 behind the tailgate.
  for (float side : {-1.f, 1.f}) {
    w.light(Vec3f(length + 0.3f, side * (hw - 0.4f), deckTop + 0.3f), std::clamp(12.f * s, 4.f, 15.f), BuildLightKind::Spot);
    w.light(Vec3f(-0.3f, side * (hw - 0.4f), deckTop + 0.2f), 4.f);
  }
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

  // Running lights 0.2 outside both deck edges and 0.2 above the deck (clear of the sponson,
  // which ends at the deck's top, and of the island, which ends at the starboard edge) every
  // ~16 units, with a bow and a stern light.
  const float runZ = deckTop + 0.2f;
  const int runs = std::max(2, int(std::lround(deckEnd / 16.f)));
  for (int k = 0; k < runs; ++k) {
    const float x = (float(k) + 0.5f) * deckEnd / float(runs);
    w.light(Vec3f(x, -0.2f, runZ), 4.f);
    w.light(Vec3f(x, beam + 0.2f, runZ), 4.f);
  }
  w.light(Vec3f(deckEnd + 0.3f, beam * 0.5f, runZ), 4.f);
  w.light(Vec3f(-0.3f, beam * 0.5f, runZ), 4.f);
  // Hangar lights 0.5 under the flight deck, one per ~12 x 16 units of the (empty) hangar.
  const int hangarX = std::max(1, int(std::lround((hx1 - hx0) / 12.f)));
  const int hangarY = std::max(1, int(std::lround((innerY1 - innerY0) / 16.f)));
  for (int j = 0; j < hangarY; ++j)
    for (int i = 0; i < hangarX; ++i)
      w.light(Vec3f(hx0 + (float(i) + 0.5f) * (hx1 - hx0) / float(hangarX),
                    innerY0 + (float(j) + 0.5f) * (innerY1 - innerY0) / float(hangarY), flightDeck - 0.5f),
              10.f);
}

}  // namespace

GeneratedBuild generateTruck(uint64_t seed, float scale) {
  requireScale(scale, 0.25, 64.0, "generateTruck");
  return runBuild("truck", [&](BuildWriter& w) { truckBody(w, seed, scale); });
}

GeneratedBuild generateCarrierShip(uint64_t seed, float scale) {
  requireScale(scale, 0.04, 64.0, "generateCarrierShip");
  return runBuild("carrier", [&](BuildWriter& w) { carrierBody(w, seed, scale); });
}

}  // namespace bw
