#pragma once
/// Contacts between convex query shapes and a voxel terrain: solid contacts against the
/// chunk triangles (for the solver) and a water estimate (for buoyancy).
///
///   std::vector<Contact> contacts;                       // reuse across frames
///   terrainContacts(terrain, QueryShape::sphere(0.5f), RigidTransform{p, q}, 0.02f, contacts);
///   WaterContact w;
///   if (terrainWaterContact(terrain, shape, pose, w)) applyBuoyancy(w.submergedVolume, w.centreOfBuoyancy);
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
/// Thread safety: terrainContacts as Terrain (it fills the cache), one thread at a time;
/// terrainContactsCached and terrainWaterContact only read.
#include <cstdint>
#include <vector>

#include "collision/bricks/contact.h"
#include "collision/bricks/query_shape.h"
#include "collision/core/rigid_transform.h"
#include "collision/terrain/terrain.h"

namespace bw {

/// Appends the solid contacts of `shape`, placed in the world by `pose` (its centre and
/// orientation), with every terrain triangle within `speculativeDistance` (depth >
/// -speculativeDistance). Returns the number appended. Throws InvalidInput for a bad shape,
/// pose or distance.
size_t terrainContacts(Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, float speculativeDistance,
                       std::vector<Contact>& out);

/// The same contacts from chunk data already in the terrain's cache, reading nothing else:
/// safe on any number of threads at once (while nothing edits the terrain or fills its cache).
/// Returns false, appending nothing, if a chunk the query needs is not cached (never meshed,
/// or evicted): the caller then runs terrainContacts on one thread. Cache hits here do not
/// refresh the cache's LRU order.
bool terrainContactsCached(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, float speculativeDistance,
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
bool terrainWaterContact(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, WaterContact& out);

}  // namespace bw
