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
#include <memory>
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

/// One terrain contact query cut into pieces that can run on different threads: a box lying
/// across many triangles costs as much as dozens of small queries, and would otherwise be one
/// job that the rest of the step waits for.
///
///   TerrainContactPlan plan;                              // reuse across frames
///   if (plan.plan(terrain, shape, pose, spec)) {          // candidate triangles, cached chunks only
///     plan.contactsOfTriangles(0, k, outA, normalsA);     // any split of [0, triangleCount()),
///     plan.contactsOfTriangles(k, n, outB, normalsB);     //   on any threads
///     // concatenate outA, outB (and normalsA, normalsB) in order, then:
///     finishTerrainContacts(out, before, normals);        // equals terrainContactsCached's
///   }
///
/// Thread safety: plan() only reads the terrain (like terrainContactsCached); once planned,
/// contactsOfTriangles is const and may run on several threads at once, while nothing edits
/// the terrain or fills its cache (it keeps pointers to cached chunk data).
class TerrainContactPlan {
 public:
  TerrainContactPlan();
  ~TerrainContactPlan();
  TerrainContactPlan(TerrainContactPlan&&) noexcept;
  TerrainContactPlan& operator=(TerrainContactPlan&&) noexcept;

  /// Gathers the triangles a query of `shape` at `pose` within `speculativeDistance` tests, in
  /// terrainContacts' order, from chunks already cached. Returns false (and plans nothing) if a
  /// chunk it needs is not cached. Throws InvalidInput as terrainContacts does.
  bool plan(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, float speculativeDistance);
  /// Candidate triangles of the last successful plan.
  uint32_t triangleCount() const { return uint32_t(triangles_.size()); }
  /// Appends the contacts of candidate triangles [begin, end) to `out`, and the world face
  /// normal of each one's triangle to `faceNormals`.
  void contactsOfTriangles(uint32_t begin, uint32_t end, std::vector<Contact>& out, std::vector<Vec3f>& faceNormals) const;

 private:
  struct BulletShapes;
  /// A chunk the query meets, with the shape placed in its frame once for all its candidate
  /// triangles: pieces of a single triangle then cost no more placing than whole queries.
  struct PlacedChunk;
  struct Triangle {
    uint32_t placed;    // its chunk in placed_
    uint32_t triangle;  // in that chunk's mesh
  };
  template <class Lookup, class ChunkDone>
  friend bool planWith(TerrainContactPlan&, const Terrain&, const QueryShape&, const RigidTransform&, float, Lookup&&,
                       ChunkDone&&);

  const Terrain* terrain_ = nullptr;
  QueryShape shape_;
  RigidTransform pose_;
  float spec_ = 0.f;
  std::vector<Triangle> triangles_;
  std::vector<PlacedChunk> placed_;
  std::unique_ptr<BulletShapes> bullet_;  // the box or hull as Bullet's GJK takes it, reused
};

/// The last step of every contact query: drops interior-edge contacts (dropInteriorEdgeContacts)
/// from out[begin, end), then keeps one of each point reported by several triangles (quad
/// diagonals, corners) with the same normal.
void finishTerrainContacts(std::vector<Contact>& out, size_t begin, const std::vector<Vec3f>& faceNormals);

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
/// otherwise). Returns false when no water voxel overlaps the box.
bool terrainWaterContact(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, WaterContact& out);
/// terrainWaterContact for a shape and pose the caller has checked already (validatePlacedShape,
/// as terrainContacts and TerrainContactPlan::plan do): the world's terrain pairs ask both.
bool terrainWaterContactChecked(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, WaterContact& out);

}  // namespace bw
