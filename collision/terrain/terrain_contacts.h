#pragma once
/// Contacts between convex query shapes and a voxel terrain: solid contacts against the
/// chunk triangles (for the solver) and a water estimate (for buoyancy).
///
///   std::vector<Contact> contacts;                       // reuse across frames
///   terrainContacts(terrain, TerrainContactShape::sphere(p, 0.5f), 0.02f, contacts);
///   WaterContact w;
///   if (terrainWaterContact(terrain, shape, w)) applyBuoyancy(w.submergedVolume, w.centreOfBuoyancy);
///
/// Pipeline per shape: terrain-local bounds -> bitmask broadphase (chunks touching solid) ->
/// chunk mesh + kD tree from the cache -> kD AABB query in chunk-local floats -> per-triangle
/// narrowphase -> contacts back in world space. Sphere and capsule use closed-form
/// closest points (one-sided: triangles are faces of a solid, so a centre behind a face
/// within the shape's reach is pushed out along the face normal). Box and hull use Bullet's
/// GJK with EPA for the deepest point, plus the shape's vertices that lie on or below the
/// triangle inside its prism when the contact is face-like, so a box resting on a face gets
/// its 4 supporting corners rather than one point.
/// Contact::featureB = (chunk coordinates mod 64/64/128 packed in 19 bits) << 13 | triangle:
/// stable while the chunk is unchanged, unique among nearby chunks.
/// Thread safety: as Terrain (the cache is filled).
#include <cstdint>
#include <vector>

#include "collision/contact.h"
#include "collision/terrain/terrain.h"

namespace bw {

/// A convex query shape in world space.
struct TerrainContactShape {
  /// Which shape this is.
  enum class Kind : uint8_t { Sphere, Capsule, Box, ConvexHull };
  Kind kind = Kind::Sphere;          ///< which fields below matter
  Vec3d position = Vec3d::Zero();    ///< world centre
  Quatf rotation = Quatf::Identity();  ///< world orientation (ignored for spheres)
  float radius = 0.f;                ///< sphere and capsule radius
  float halfHeight = 0.f;            ///< capsule: half length of the core segment along local Y
  Vec3f halfExtents = Vec3f::Zero(); ///< box half extents
  const Vec3f* hullPoints = nullptr; ///< hull points in the shape's frame (caller keeps them alive)
  uint32_t hullPointCount = 0;       ///< number of hull points
  float hullVolume = 0.f;            ///< volume of the hull (computed by convexHull())

  /// A sphere.
  static TerrainContactShape sphere(const Vec3d& centre, float radius);
  /// A capsule whose core segment runs along its local Y axis.
  static TerrainContactShape capsule(const Vec3d& centre, const Quatf& rotation, float halfHeight, float radius);
  /// A box.
  static TerrainContactShape box(const Vec3d& centre, const Quatf& rotation, const Vec3f& halfExtents);
  /// The convex hull of `count` points (>= 4, not coplanar); computes its volume once.
  static TerrainContactShape convexHull(const Vec3d& centre, const Quatf& rotation, const Vec3f* points, uint32_t count);

  /// Volume of the shape.
  float volume() const;
  /// Throws InvalidInput for NaN/inf or non-positive sizes.
  void validate(const char* context) const;
};

/// Appends the shape's solid contacts with every terrain triangle within
/// `speculativeDistance` (depth > -speculativeDistance). Returns the number appended.
size_t terrainContacts(Terrain& terrain, const TerrainContactShape& shape, float speculativeDistance,
                       std::vector<Contact>& out);

/// Interior edges: a shape resting on a flat area made of many triangles touches the
/// neighbours of its supporting triangle at their shared (quad diagonal or quad border) edges,
/// which yields tilted normals that make it jitter. Removes from out[begin, end) every contact
/// whose normal differs from its own triangle's face normal when another contact there has its
/// face normal, lies on a coplanar triangle and has the edge contact's point in its plane.
/// faceNormals[i - begin] is the world face normal of contact i's triangle. terrainContacts
/// applies it to its own output.
void dropInteriorEdgeContacts(std::vector<Contact>& out, size_t begin, const std::vector<Vec3f>& faceNormals);

/// Water in contact with a shape, for buoyancy.
struct WaterContact {
  double submergedVolume = 0;                ///< estimated volume of the shape under water
  Vec3d centreOfBuoyancy = Vec3d::Zero();    ///< world centroid of that volume
  float submergedFraction = 0.f;             ///< submergedVolume / shape volume, in [0, 1]
};

/// Estimates the water volume the shape displaces: the overlap of the shape's terrain-local
/// bounding box with each water voxel's filled part (occupancy / 255 of the cell from its
/// bottom), scaled by shape volume / box volume (exact for an axis-aligned box, an estimate
/// otherwise). Returns false when the broadphase sees no water.
bool terrainWaterContact(const Terrain& terrain, const TerrainContactShape& shape, WaterContact& out);

}  // namespace bw
