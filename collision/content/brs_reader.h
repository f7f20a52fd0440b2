#pragma once
/// Reader for Brickadia saves (.brs, format versions 8 to 10) that turns them into our bricks.
///
///   bw::BrsLoadResult save = bw::loadBrs("../shared/data/Lighthouse_Island.brs");
///   for (const bw::Brick& b : save.bricks) grid.placeBrick(b);
///
/// Everything is read from one buffer; every read is checked against the bytes left, and a bad
/// file throws bw::InvalidInput("<file>: <section>: <problem>") before anything is returned, so a
/// caller never sees a half-loaded save.
///
/// ## File layout (all integers little endian)
/// ```
/// "BRS" u16 version (8..10) i32 gameVersion
/// section header1   map, authorName, description : string; authorId : uuid;
///                   hostName : string; hostId : uuid; saveTime : 8 bytes; brickCount : i32
/// section header2   mods : string[]; brickAssets : string[]; colors : u32[] (BGRA);
///                   materials : string[]; owners : {uuid, name string, i32 bricks}[];
///                   v9+: physicalMaterials : string[]
/// u8 previewFormat; if != 0: i32 length, then that many bytes (an image we skip)
/// section bricks    bit stream, brickCount records (below)
/// section components i32 count, then count x {name : string, i32 byteLength, byteLength bytes}
///                   (each component's bytes: a bit stream, below)
/// ```
/// A section is `i32 uncompressedSize, i32 compressedSize` then compressedSize bytes of zlib data
/// (or, when compressedSize is 0, uncompressedSize raw bytes); compressedSize must be smaller
/// than uncompressedSize. A string is `i32 n`: n > 0 is n bytes of Latin-1 text ending in NUL,
/// n < 0 is -n UTF-16 code units (we keep the low byte of each); an array is `i32 count` + items.
///
/// ## Brick record (bit stream, least significant bit of each byte first)
/// `uint(max)` reads bits LSB first while value + nextBit < max (so max <= 1 reads nothing);
/// `packed` is up to 5 groups of [1 "more" bit, 7 value bits]; `spacked` is packed v with
/// magnitude v >> 1 and sign + when v & 1, - otherwise.
/// ```
/// align to a byte
/// asset        uint(max(assetCount, 2))
/// hasSize      1 bit; if set: size = 3 x packed (half extents x, y, z; procedural bricks)
/// position     3 x spacked (centre x, y, z)
/// orientation  uint(24): direction = (o >> 2) % 6, rotation = o & 3
/// collision    v8, v9: 1 bit; v10: 4 bits (player, weapon, interaction, tool)
/// visibility   1 bit
/// material     uint(max(materialCount, 2))
/// v9+:         physicalMaterial uint(max(physicalCount, 2)), materialIntensity uint(11)
/// color        1 bit; set: v8 4 bytes BGRA, v9+ 3 bytes RGB (as 32 / 24 bits); clear: uint(colorCount)
/// owner        packed (0 = none, else owner index + 1)
/// ```
/// A brick is indexed when its collision bit is set (v10: the player bit, the one that stops
/// bodies); the others are counted in collisionOff.
///
/// ## Component data (bit stream, same bit order; nothing in it is byte aligned)
/// A component (a light, an interaction, ...) lists the bricks that carry it and one value per
/// declared property for each of them. Strings inside the stream are .brs strings (i32 n, then
/// the bytes) starting at any bit. Verified on Lighthouse_Island (BCD_PointLight, 714 bytes, and
/// BCD_SpotLight, 1017 bytes, both decode to their last byte).
/// ```
/// version      32 bits (i32; 1 in Lighthouse_Island)
/// bricks       i32 count, then count x uint(max(brickCount, 2)) record indices (< brickCount)
/// properties   i32 count, then count x {name : string, type : string}
/// values       for each brick index in order, for each property in order, by type:
///              Boolean 32 bits (0 or 1)   Float 32-bit IEEE   Color 4 bytes BGRA   Byte 8 bits
///              Rotator 3 floats (pitch, yaw, roll, degrees)   Class, Object, String: a string
///              (and, from public readers, not seen in a save we have: Integer 32 bits,
///              Integer64 64 bits, Double 64 bits, IntVector 3 x 32 bits)
/// padding      up to the next byte: the values end in the component's last byte (Lighthouse_Island:
///              1 and 4 zero bits; their values are not checked); 8 or more bits left is an error
/// ```
/// Any other type cannot be sized, so the component cannot be decoded: an error naming it. The
/// section ends with its last component (bytes after it are an error).
///
/// Lights: every brick listed by BCD_PointLight (properties in Lighthouse_Island:
/// bMatchBrickShape Boolean, Brightness Float, Radius Float, Color Color, bUseBrickColor
/// Boolean, bCastShadows Boolean) or BCD_SpotLight (Rotation Rotator, InnerConeAngle Float,
/// OuterConeAngle Float, then the point light's Brightness to bCastShadows without
/// bMatchBrickShape) gives a BuildLight at its brick's centre, collision on or off (a lamp's
/// glass often has none). Its radius is the Radius property in Brickadia units times
/// unitsPerBrsUnit; a missing or non-positive Radius gives kBrsDefaultLightRadius, a NaN or
/// infinite one is an error. Only the position, radius and kind are kept.
///
/// ## Units and frame
/// Brickadia units: 10 per stud across, 4 per plate of height (a brick is 12); `size` is a half
/// extent, `position` the centre, Z up. Positions and sizes are multiplied by unitsPerBrsUnit
/// (default 0.04: one stud = 0.4 of our units, like our generators). Coordinates are taken as
/// they are: Brickadia's frame is Unreal's (left-handed), so the import is the mirror image of
/// what the game shows (Y flipped). Every shape we map to is its own mirror image up to a
/// rotation, so counts, bounds, volumes and contacts are unaffected.
///
/// ## Orientation
/// Brickadia's orientation (d, r) turns a brick's local frame by M = D(d) * Rz(r * 90 deg):
/// Rz turns counter-clockwise about +Z ((x, y, z) -> (-y, x, z)); D(d) takes local +Z to the
/// direction d (0..5 = +X, -X, +Y, -Y, +Z, -Z):
/// ```
/// +X: (x, y, z) -> ( z, -y,  x)     -X: -> (-z,  y,  x)     +Y: -> ( y,  z,  x)
/// -Y: (x, y, z) -> (-y, -z,  x)     +Z: -> ( x,  y,  z)     -Z: -> (-x,  y, -z)
/// ```
/// (the rotation table of the public brs-js helpers, and consistent with the axis permutation
/// its bounds code uses). Our AxisRotation also names where local +Z points, but picks other
/// base rotations for the X and Y directions, so the spins differ there; brsOrientation()
/// finds our rotation with exactly the same matrix (a table built once from the 24 matrices).
/// (d = +Z, r = 0) is our identity; for +Z, r is our spin. Checked on Lighthouse_Island: with
/// this mapping no wedge's solid half overlaps a neighbour, and most side wedges pair up with a
/// neighbour filling their cut-off half (tests/collision/brs_reader_test.cpp).
///
/// ## Shapes
/// Procedural assets ("PB_..." with a size in the record), Brickadia canonical shape -> ours.
/// `fold` turns our canonical shape into Brickadia's; the brick's rotation is M * fold, and
/// halfSize is Brickadia's size permuted so that the folded shape has Brickadia's extents.
/// ```
/// PB_DefaultBrick, _Tile, _MicroBrick, _Studded       box                       fold identity
/// PB_DefaultWedge   full height at -x sloping down to +x      Wedge            fold identity
/// PB_DefaultRamp    1-stud flat top at -x, slope to +x        Wedge (top strip and 2-unit lip
///                                                               dropped)       fold identity
/// PB_DefaultRampInverted  the ramp upside down                Wedge  fold = 180 deg about x
/// PB_DefaultSideWedge, _SideWedgeTile, _MicroWedge
///                   prism along z, triangle (-x,-y) (+x,-y) (-x,+y): the +x+y corner cut off
///                                                             Wedge  fold = -90 deg about x,
///                                                             halfSize (sx, sz, sy)
/// PB_DefaultRampCorner, _MicroWedgeCorner  apex over (-x,-y)  CornerWedge      fold identity
/// PB_DefaultRampInnerCorner (a box minus a corner)            box (its convex hull)
/// other PB_ assets with a size                                box of that size, counted as unknown
/// ```
/// Fixed-shape assets ("B_...", no size in the record) use kBrsFixedAssets: a half size in
/// Brickadia units and a box or a cylinder (round: 16 sides, octo: 8 sides, along local z).
/// Unknown fixed assets become a 1x1 brick box (5 x 5 x 6) and are counted in unknownAssets.
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "collision/bricks/brick.h"
#include "collision/content/build_light.h"
#include "collision/core/aabb.h"
#include "collision/core/axis_rotation.h"

namespace bw {

/// One brick record as stored in the file (Brickadia units), kept for tools and tests.
struct BrsBrickRecord {
  int32_t position[3] = {0, 0, 0};   ///< centre
  uint32_t size[3] = {0, 0, 0};      ///< half extents from the record (0 when the asset is fixed-shape)
  uint32_t halfSizeUsed[3] = {0, 0, 0};  ///< the record's size, or the asset table's for fixed shapes
  uint32_t asset = 0;                ///< index into BrsLoadResult::assetNames
  int32_t brick = -1;                ///< index into BrsLoadResult::bricks (-1: collision off)
  uint8_t direction = 4;             ///< 0..5 = +X, -X, +Y, -Y, +Z, -Z
  uint8_t rotation = 0;              ///< 0..3 quarter turns
  bool collision = true;             ///< v10: the player collision bit
  bool hasSize = false;              ///< the record carried a size (procedural brick)
};

/// A fixed-shape asset's stand-in: half size in Brickadia units and shape.
struct BrsFixedAsset {
  const char* name;      ///< asset name as stored in header 2
  uint16_t halfSize[3];  ///< Brickadia units, local x, y, z
  BrickShape shape;      ///< Box or Cylinder (a prism along local z)
  uint8_t sides;         ///< cylinders only
};

/// The documented fixed-shape assets (every one in Lighthouse_Island and some common others).
std::span<const BrsFixedAsset> brsFixedAssets();

/// Our rotation with the same matrix as Brickadia's (direction 0..5, rotation 0..3).
AxisRotation brsOrientation(int direction, int rotation);

/// Radius of a light whose component has no positive Radius, in Brickadia units: the point
/// light radius most of Lighthouse_Island's lamps use (150 units, 15 studs; 6 of our units).
constexpr float kBrsDefaultLightRadius = 150.f;

/// What a .brs file turned into.
struct BrsLoadResult {
  std::vector<Brick> bricks;                      ///< bricks with collision on, in our units
  uint32_t totalBricks = 0;                       ///< records in the file
  uint32_t collisionOff = 0;                      ///< records not indexed (collision off)
  std::map<std::string, uint32_t> assetCounts;    ///< records per asset name
  std::map<std::string, uint32_t> shapeCounts;    ///< records per our shape ("box", "wedge", ...)
  uint32_t unknownAssets = 0;                     ///< records whose asset had no mapping (box used)
  Aabb bounds = Aabb::empty();                    ///< of the imported bricks, our units
  int version = 0;                                ///< save format version
  int32_t gameVersion = 0;                        ///< game changelist that wrote the save
  std::string mapName, author, description;       ///< from header 1
  std::vector<std::string> assetNames;            ///< header 2 brick asset table
  std::vector<BrsBrickRecord> records;            ///< every record, in file order
  std::map<std::string, uint32_t> componentCounts;  ///< bricks per component name
  /// Lights of the BCD_PointLight and BCD_SpotLight components, in file order (component by
  /// component, its bricks as listed), grid-local in our units.
  std::vector<BuildLight> lights;
  std::vector<uint32_t> lightRecords;             ///< per light: index into records of its brick
  /// Bricks carrying a component named "...Light" (found); lights.size() of them were used. The
  /// two differ when a save has a light component we do not know.
  uint32_t lightComponentsFound = 0;
};

/// Reads and converts a .brs file. Throws InvalidInput naming the file and the problem.
BrsLoadResult loadBrs(const std::string& path, float unitsPerBrsUnit = 0.04f);

/// The same from bytes in memory; nameForErrors starts every error message.
BrsLoadResult parseBrs(const uint8_t* data, size_t size, const std::string& nameForErrors,
                       float unitsPerBrsUnit = 0.04f);

/// Name of a shape as used in BrsLoadResult::shapeCounts ("box", "wedge", "corner_wedge", "cylinder").
const char* brickShapeName(BrickShape shape);

}  // namespace bw
