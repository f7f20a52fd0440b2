#pragma once
/// Seeded generators of whole brick builds for tests, benchmarks and scenes (issue 4).
///
/// Every generator is a pure function of (seed, scale): the same arguments give byte-identical
/// bricks on every platform (bw::SeededRandom only, no std:: distributions and no
/// transcendental functions in any decision). Z is up: a brick at rest has AxisRotation
/// identity (local +Z along grid +Z). Units: a standard brick is 0.4 x 0.4 x 0.48, a plate
/// 0.16 tall, a microbrick 0.08.
///
/// Bricks are laid next to each other like a real build (walls in running bond, floors tiled),
/// so they touch but do not overlap. The output vector is sized exactly before it is filled:
/// each generator runs once to count, reserves, then runs again to write.
///
/// Lights: each build also lists the lights a game would give it (ceiling lamps, head lights,
/// running lights, street lamps; see each generator), placed in open space (never inside a
/// brick's box), with radii of 4 to 15 units, also a pure function of (seed, scale). They are
/// derived from the build's dimensions and its existing random draws only, so adding them left
/// every brick unchanged.
///
/// Scale law: for every build the brick count grows about linearly with `scale`. Shell builds
/// (house, truck, carrier, ring station) grow their linear dimensions with sqrt(scale), the plate
/// stack adds plates, the city block adds lots, ramps and microbrick patches.
///
/// | build        | scale 1        | scale range     |
/// |--------------|----------------|-----------------|
/// | house        | ~5k bricks     | 0.25 .. 64      |
/// | truck        | ~3k bricks     | 0.25 .. 64      |
/// | carrier      | ~50k bricks    | 0.04 .. 64      |
/// | ring_station | ~100k bricks   | 0.01 .. 64      |
/// | plate_stack  | 300 plates     | 0.01 .. 64      |
/// | city_block   | ~2M bricks     | 0.001 .. 8      |
/// | chain_link   | 216 bricks     | 0.1 .. 64 (scales lengths, not the count) |
/// | hangar       | ~1.5k bricks   | 0.25 .. 16      |
#include <cstdint>
#include <string>
#include <vector>

#include "collision/bricks/brick.h"
#include "collision/content/build_light.h"
#include "collision/core/aabb.h"

namespace bw {

/// Material ids the generators assign (the world maps ids to density and friction tables).
enum class BuildMaterial : uint8_t { Concrete = 0, Masonry, Wood, Glass, Metal, Rubber, Plastic, Asphalt };

/// Filter bit of load-bearing structure (walls, floors, hulls, ramps).
constexpr uint32_t kBuildFilterStructure = 1u;
/// Filter bit of small detail (furniture, microbricks, props), so queries can skip it.
constexpr uint32_t kBuildFilterDetail = 2u;

/// A named run [begin, end) of GeneratedBuild::bricks, e.g. "walls", "bed", "floor".
/// Parts are contiguous, in generation order, and together cover every brick; a name may repeat.
struct BuildPart {
  std::string name;    ///< what the bricks are ("walls", "floor", "ramps", ...)
  uint32_t begin = 0;  ///< index of the first brick
  uint32_t end = 0;    ///< one past the last brick
};

/// Dimensions of the ring station (zero for other builds). The ring's axis is grid Z through
/// the origin; the floor faces the axis, so "down" inside the ring points away from it.
struct RingDimensions {
  float innerRadius = 0.f;  ///< radius where the ceiling cells start (innermost skin)
  float floorRadius = 0.f;  ///< radius where the floor cells start (the walking surface)
  float width = 0.f;        ///< extent of the habitable band along Z, centred on z = 0
};

/// One generated build.
struct GeneratedBuild {
  std::string name;           ///< the generateBuild name ("house", "truck", ...)
  std::vector<Brick> bricks;  ///< grid-local bricks, Z up, in part order
  /// Union of every brick's rotated box (exact for all shapes the generators emit: their
  /// cylinders have a multiple of 4 sides, so every shape reaches all six faces of its box).
  Aabb bounds = Aabb::empty();
  /// Open spaces no brick reaches into: truck -> {bed}, carrier -> {hangar}; empty otherwise.
  std::vector<Aabb> interiors;
  /// Named runs of bricks (see BuildPart).
  std::vector<BuildPart> parts;
  /// Set by the ring station only.
  RingDimensions ring;
  /// Lights of the build (grid-local, in open space), in generation order.
  std::vector<BuildLight> lights;
};

/// A house of round(1.8 * sqrt(scale)) storeys (at least one; two at scale 1): baseplates, floor plates, running-bond
/// brick walls with window and door holes, a partition wall per storey, furniture of small
/// bricks, a hip roof of wedges with corner wedges, porch pillars (cylinders).
/// Lights: ceiling lamps in every room of every storey (one per ~8 x 8 units of room, at least
/// one) and a porch lamp under the porch roof (5 at scale 1).
/// Throws InvalidInput naming `scale` unless 0.25 <= scale <= 64.
GeneratedBuild generateHouse(uint64_t seed, float scale);

/// A truck: frame rails and deck, cylinder wheels on horizontal (Y) axles, a cab with
/// windows, seats and a wedge fairing, and an open bed (floor + low side walls + tailgate,
/// nothing above it). interiors[0] is the bed's open space, up to 2 units above its walls.
/// Lights: two head lights (Spot) in front of the headlight bricks and two tail lights behind
/// the tailgate (4 at every scale).
/// Throws InvalidInput naming `scale` unless 0.25 <= scale <= 64.
GeneratedBuild generateTruck(uint64_t seed, float scale);

/// A carrier ship along +X: hull shell with a raked bow of wedges, internal decks and
/// bulkheads, an enclosed hangar (floor, walls, the flight deck as ceiling, a large opening
/// in the starboard side), flight deck with markings and arresting wires, an island tower with
/// a mast, parked aircraft. interiors[0] is the hangar's open space.
/// Lights: running lights just outside both deck edges every ~16 units plus bow and stern
/// lights, and a grid of hangar lights under the flight deck (56 at scale 1).
/// Throws InvalidInput naming `scale` unless 0.04 <= scale <= 64.
GeneratedBuild generateCarrierShip(uint64_t seed, float scale);

/// A ring station around grid Z, pixelated on a 0.4 lattice (axis-aligned bricks only): floor
/// cells facing the axis (their local +Z points at the axis), ceiling with windows, side walls,
/// modules standing on the floor, a hub and four spokes. `ring` holds its dimensions.
/// Lights: one per ~10 units of the ring (a multiple of 4, at least 8) in the band just under
/// the ceiling that modules never reach, at z = 0 (44 at scale 1).
/// Throws InvalidInput naming `scale` unless 0.01 <= scale <= 64.
GeneratedBuild generateRingStation(uint64_t seed, float scale);

/// The article's worst case for loose octrees: round(300 * scale) (at least 3) large flat
/// plates (64 x 64 or 64 x 48, 0.16 thick) stacked on top of each other with small offsets.
/// No lights.
/// Throws InvalidInput naming `scale` unless 0.01 <= scale <= 64.
GeneratedBuild generatePlateStackBricks(uint64_t seed, float scale);

/// A city block: baseplate streets, buildings of 3..14 storeys (running-bond walls with
/// windows, floors, lobby pillars, flat or hip roofs), 500-long ramps (Wedge, half size
/// (250, 4, 2)) and patches of 0.08 microbricks right next to the ramps.
/// ~2M bricks at scale 1, ~20k at scale 0.01; the ramps stay 500 long at every scale.
/// Lights: a lamp in each building's ground-floor lobby, and street lamps 4.5 above the street
/// centre lines every 20 units (835 at scale 1, 61 at scale 0.05).
/// Throws InvalidInput naming `scale` unless 0.001 <= scale <= 8.
GeneratedBuild generateCityBlock(uint64_t seed, float scale);

/// Dimensions of a chain link (generateChainLink) at a scale.
struct LinkDimensions {
  float cell = 0.f;        ///< edge of the cells the wire is made of (its bricks are runs of them)
  float wireRadius = 0.f;  ///< radius of the wire (the link's bar)
  float arcRadius = 0.f;   ///< radius of the centre line's end arcs
  float straight = 0.f;    ///< length of the centre line's straight sides (along Z)
  Aabb hole;               ///< a box inside the link's hole that no brick reaches into
};
LinkDimensions chainLinkDimensions(float scale);

/// A chain link of microbricks in the grid's XZ plane, long along Z and centred on the origin:
/// a wire of radius 0.24 x scale around a stadium centre line (straight sides 0.96 x scale
/// long, end arcs of radius 0.72 x scale) of 0.08 x scale cells, each run of cells along Z one
/// brick (216 bricks at every scale: scale multiplies every length). Another link fits through
/// its hole (interiors[0], chainLinkDimensions(scale).hole): two links turned a quarter about Z
/// from each other, their centres on the Z axis less than the hole's inner length (straight +
/// 2 (arcRadius - wireRadius)) apart, interlock without touching. The seed is unused (a link
/// has one shape). No lights.
/// Throws InvalidInput naming `scale` unless 0.1 <= scale <= 64.
GeneratedBuild generateChainLink(uint64_t seed, float scale);

/// A docking hangar: a slot open at x = 0 and closed at its back (x = length), 96 x 16 x 24
/// inside at scale 1 (each grown with sqrt(scale)), its floor's top at z = 0: a floor and roof
/// of 3.2 x 3.2 x 0.8 plates, side walls of 3.2 x 0.8 x 1.6 panels in running bond with seeded
/// glass panels, a back wall, and a frame of beams around the outside every 8 units (the first
/// one rims the mouth). interiors[0] is the slot. Its convex hull closes the mouth: a ship
/// flying in meets the hangar's bricks only with two-way grid pairs.
/// Lights: one under the roof every 8 units along the slot (12 at scale 1).
/// Throws InvalidInput naming `scale` unless 0.25 <= scale <= 16.
GeneratedBuild generateHangar(uint64_t seed, float scale);

/// Names accepted by generateBuild, in a fixed order.
std::vector<std::string> buildNames();

/// Dispatches by name ("house", "truck", "carrier", "ring_station", "plate_stack",
/// "city_block", "chain_link", "hangar"); throws InvalidInput listing the valid names for any other.
GeneratedBuild generateBuild(const std::string& name, uint64_t seed, float scale);

}  // namespace bw
