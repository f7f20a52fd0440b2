#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <memory>
#include <random>
#include <vector>

#include "collision/content/terrain_generator.h"
#include "collision/core/argument_checks.h"
#include "collision/terrain/chunk_mesher.h"
#include "collision/terrain/terrain_contacts.h"
#include "collision/terrain/triangle_contacts.h"

namespace bw {
namespace {

/// A query shape and where it is (the terrain queries take both).
struct Placed {
  QueryShape shape;
  RigidTransform pose;
};
Placed sphereAt(const Vec3d& centre, float radius) { return {QueryShape::sphere(radius), {centre, Quatf::Identity()}}; }
Placed boxAt(const Vec3d& centre, const Quatf& rotation, const Vec3f& half) { return {QueryShape::box(half), {centre, rotation}}; }
/// A capsule whose core runs along its local z axis.
Placed capsuleAt(const Vec3d& centre, const Quatf& rotation, float halfHeight, float radius) {
  return {QueryShape::capsule(radius, halfHeight), {centre, rotation}};
}
size_t terrainContacts(Terrain& terrain, const Placed& p, float spec, std::vector<Contact>& out) {
  return bw::terrainContacts(terrain, p.shape, p.pose, spec, out);
}
bool terrainWaterContact(const Terrain& terrain, const Placed& p, WaterContact& out) {
  return bw::terrainWaterContact(terrain, p.shape, p.pose, out);
}

/// A flat solid floor whose top surface is at y = 4 (terrain-local).
std::unique_ptr<Terrain> flatTerrain(const RigidTransform& place = {}) {
  auto t = std::make_unique<Terrain>(Int3{32, 16, 32}, 1.f, place);
  t->fillBox({0, 0, 0}, {31, 3, 31}, Voxel::make(7));
  return t;
}

TEST(TerrainContacts, SphereContactsMatchBruteForceOverAllTriangles) {
  Terrain terrain({32, 20, 32}, 1.f);
  terrain.edit({0, 0, 0}, {31, 19, 31}, [](VoxelTerrain& v) { generateRandomTerrain(v, 51, 0.03f); });
  // Brute force: every triangle of every chunk, terrain-local, same per-triangle primitive.
  std::vector<Vec3f> tris;
  ChunkNeighbourhood n;
  ChunkMesh mesh;
  for (int cy = 0; cy < 3; ++cy)
    for (int cz = 0; cz < 4; ++cz)
      for (int cx = 0; cx < 4; ++cx) {
        terrain.voxels().gatherNeighbourhood({cx, cy, cz}, n);
        meshChunk(n, 1.f, mesh);
        for (uint16_t i : mesh.indices) tris.push_back(mesh.vertex(i) + Vec3f(float(cx * 8), float(cy * 8), float(cz * 8)));
      }
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> pos(-2.f, 34.f), rad(0.2f, 2.5f);
  std::vector<Contact> contacts;
  size_t total = 0;
  for (int q = 0; q < 300; ++q) {
    const Vec3f c(pos(rng), pos(rng) * 0.6f, pos(rng));
    const float r = rad(rng);
    std::vector<Contact> brute;
    std::vector<Vec3f> faces;
    for (size_t t = 0; t < tris.size(); t += 3) {
      const Vec3f nrm = (tris[t + 1] - tris[t]).cross(tris[t + 2] - tris[t]).normalized();
      TriangleContact lc;
      if (sphereTriangle(c, r, tris[t], tris[t + 1], tris[t + 2], nrm, 0.05f, lc)) {
        brute.push_back({lc.point.cast<double>(), lc.normal, lc.depth, 0, 0});
        faces.push_back(nrm);
      }
    }
    dropInteriorEdgeContacts(brute, 0, faces);
    std::vector<float> want;
    for (const Contact& k : brute) want.push_back(k.depth);
    contacts.clear();
    terrainContacts(terrain, sphereAt(c.cast<double>(), r), 0.05f, contacts);
    std::vector<float> got;
    for (const Contact& k : contacts) got.push_back(k.depth);
    // Duplicate points are merged by terrainContacts; compare the distinct depths and counts.
    ASSERT_LE(got.size(), want.size()) << q;
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    if (!want.empty()) {
      ASSERT_FALSE(got.empty()) << q;
      EXPECT_NEAR(got.back(), want.back(), 1e-4f) << q;
    }
    for (float d : want) {
      const bool present = std::any_of(got.begin(), got.end(), [&](float g) { return std::abs(g - d) < 1e-4f; });
      ASSERT_TRUE(present) << "query " << q << " lost a contact of depth " << d;
    }
    total += got.size();
  }
  EXPECT_GT(total, 100u);
}

TEST(TerrainContacts, SphereOnFlatGroundFarFromOriginAndRotated) {
  const RigidTransform place{Vec3d(3.0e7, 1.0e6, -2.0e7), Quatf(Eigen::AngleAxisf(0.4f, Vec3f(1, 0.5f, 0).normalized()))};
  for (const RigidTransform& p : {RigidTransform{}, place}) {
    const auto holder = flatTerrain(p);
    Terrain& terrain = *holder;
    const Vec3d localCentre(10.3, 4.0 + 0.5 - 0.1, 12.6);
    const Vec3d centre = p.translation + p.rotation.cast<double>() * localCentre;
    std::vector<Contact> contacts;
    ASSERT_EQ(terrainContacts(terrain, sphereAt(centre, 0.5f), 0.f, contacts), 1u);
    const Contact& c = contacts[0];
    EXPECT_NEAR(c.depth, 0.1f, 1e-4f);
    EXPECT_LT((c.normal - p.directionToWorld(Vec3f(0, 1, 0))).norm(), 1e-5f);
    const Vec3d expect = p.translation + p.rotation.cast<double>() * Vec3d(10.3, 4.0, 12.6);
    EXPECT_LT((c.position - expect).norm(), 1e-4);
    EXPECT_EQ(c.material, 7u);
    // Deep: centre 0.2 below the surface, still pushed up along the face normal.
    contacts.clear();
    const Vec3d deep = p.translation + p.rotation.cast<double>() * Vec3d(10.3, 3.8, 12.6);
    ASSERT_GE(terrainContacts(terrain, sphereAt(deep, 0.5f), 0.f, contacts), 1u);
    EXPECT_NEAR(contacts[0].depth, 0.7f, 1e-4f);
    EXPECT_LT((contacts[0].normal - p.directionToWorld(Vec3f(0, 1, 0))).norm(), 1e-5f);
  }
}

TEST(TerrainContacts, ShapesAcrossChunkBordersGetOneConsistentManifold) {
  const auto holder = flatTerrain();
  Terrain& terrain = *holder;
  std::vector<Contact> contacts;
  // A sphere right above the corner shared by four chunks (x = z = 8): the four chunks' quads
  // all touch it at the same point; exactly one contact survives, along the face normal.
  terrainContacts(terrain, sphereAt(Vec3d(8, 4.4, 8), 0.5f), 0.f, contacts);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_NEAR(contacts[0].depth, 0.1f, 1e-5f);
  EXPECT_GT(contacts[0].normal.y(), 0.99999f);
  // A box straddling the x = 16 border: its four corners, nothing tilted.
  contacts.clear();
  terrainContacts(terrain, boxAt(Vec3d(16.1, 4.45, 5.3), Quatf::Identity(), Vec3f(0.7f, 0.5f, 0.4f)), 0.f, contacts);
  int corners = 0;
  for (const Contact& c : contacts) {
    EXPECT_GT(c.normal.y(), 0.999f);
    EXPECT_NEAR(c.depth, 0.05f, 1e-3f);
    corners += std::abs(std::abs(c.position.x() - 16.1) - 0.7) < 1e-4 && std::abs(std::abs(c.position.z() - 5.3) - 0.4) < 1e-4;
  }
  EXPECT_EQ(corners, 4);
}

TEST(TerrainContacts, SphereOnAStepEdgeGetsADiagonalNormal) {
  const auto holder = flatTerrain();
  Terrain& terrain = *holder;
  terrain.fillBox({0, 4, 0}, {9, 4, 31}, Voxel::make(3));  // a step up to y = 5 for x < 10
  std::vector<Contact> contacts;
  // Centre beyond the step's edge line (x = 10, y = 5), diagonally out, 0.05 penetrating.
  const double off = (0.5 - 0.05) / std::sqrt(2.0);
  terrainContacts(terrain, sphereAt(Vec3d(10 + off, 5 + off, 15.5), 0.5f), 0.f, contacts);
  ASSERT_FALSE(contacts.empty());
  float deepest = 0.f;
  for (const Contact& c : contacts) deepest = std::max(deepest, c.depth);
  EXPECT_NEAR(deepest, 0.05f, 1e-4f);
  EXPECT_NEAR(contacts[0].normal.x(), std::sqrt(0.5f), 1e-3f);
  EXPECT_NEAR(contacts[0].normal.y(), std::sqrt(0.5f), 1e-3f);
}

TEST(TerrainContacts, BoxRestingOnGroundIsSupportedAtItsFourCorners) {
  const auto holder = flatTerrain();
  Terrain& terrain = *holder;
  std::vector<Contact> contacts;
  terrainContacts(terrain, boxAt(Vec3d(10.3, 4.5 - 0.05, 10.4), Quatf::Identity(), Vec3f(0.5f, 0.5f, 0.5f)), 0.f,
                  contacts);
  ASSERT_GE(contacts.size(), 4u);
  int corners = 0;
  for (const Contact& c : contacts) {
    EXPECT_NEAR(c.depth, 0.05f, 1e-3f);
    EXPECT_GT(c.normal.dot(Vec3f(0, 1, 0)), 0.999f);
    EXPECT_NEAR(c.position.y(), 4.0, 1e-4);
    const bool corner = std::abs(std::abs(c.position.x() - 10.3) - 0.5) < 1e-4 && std::abs(std::abs(c.position.z() - 10.4) - 0.5) < 1e-4;
    corners += corner;
  }
  EXPECT_EQ(corners, 4);
  // A box tilted 45 degrees about Z lands on an edge: its lowest edge penetrates by 0.05.
  contacts.clear();
  const Quatf tilt(Eigen::AngleAxisf(float(M_PI / 4), Vec3f::UnitZ()));
  const double h = 0.5 * std::sqrt(2.0);
  terrainContacts(terrain, boxAt(Vec3d(10.3, 4.0 + h - 0.05, 10.4), tilt, Vec3f(0.5f, 0.5f, 0.5f)), 0.f, contacts);
  ASSERT_FALSE(contacts.empty());
  float deepest = 0.f;
  for (const Contact& c : contacts) deepest = std::max(deepest, c.depth);
  EXPECT_NEAR(deepest, 0.05f, 1e-3f);
  // Out of reach: nothing; within the speculative distance: negative depth.
  contacts.clear();
  EXPECT_EQ(terrainContacts(terrain, boxAt(Vec3d(10.3, 4.6, 10.4), Quatf::Identity(), Vec3f(0.5f, 0.5f, 0.5f)), 0.f,
                            contacts),
            0u);
  EXPECT_GE(terrainContacts(terrain, boxAt(Vec3d(10.3, 4.6, 10.4), Quatf::Identity(), Vec3f(0.5f, 0.5f, 0.5f)),
                            0.2f, contacts),
            1u);
  EXPECT_NEAR(contacts[0].depth, -0.1f, 1e-3f);
}

TEST(TerrainContacts, TumblingBoxesReportTheirDeepestCornerUnderFlatGround) {
  // Seeded boxes (0.1-0.6 m half sizes) at random rotations, their centres above the ground
  // and some corner under it, on voxels of 0.5 m far from the origin: the deepest contact
  // equals the deepest corner (brute force over the 8 corners). note: before the fix, EPA's
  // depth against a lone ground triangle (a shallow slide off its edge) capped the corners
  // taken, and 29% of these boxes had a corner sunk up to 0.4 m reported shallower or not at
  // all: tumbling crates sank into flat ground (quarry).
  const RigidTransform place{Vec3d(40000, -25000, 120), Quatf::Identity()};
  Terrain terrain({64, 64, 16}, 0.5f, place);
  terrain.fillBox({0, 0, 0}, {63, 63, 3}, Voxel::make(2));  // top at local z = 2
  std::mt19937 rng(17);
  auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  int underReported = 0;
  for (int i = 0; i < 1000; ++i) {
    const Vec3f axis = Vec3f(float(uniform(-1, 1)), float(uniform(-1, 1)), float(uniform(-1, 1))).normalized();
    const Quatf q(Eigen::AngleAxisf(float(uniform(0, M_PI)), axis));
    const Vec3f half(float(uniform(0.1, 0.6)), float(uniform(0.1, 0.6)), float(uniform(0.1, 0.6)));
    const Eigen::Matrix3f R = q.toRotationMatrix();
    const double reach = (R.cwiseAbs() * half).z();
    const Vec3d local(uniform(8, 24), uniform(8, 24), 2.0 + uniform(0.05, 0.95) * reach);
    float deepestCorner = 0.f;
    for (int k = 0; k < 8; ++k) {
      const Vec3f v((k & 1) ? half.x() : -half.x(), (k & 2) ? half.y() : -half.y(), (k & 4) ? half.z() : -half.z());
      deepestCorner = std::max(deepestCorner, float(2.0 - (local.z() + (R * v).z())));
    }
    std::vector<Contact> out;
    terrainContacts(terrain, boxAt(place.translation + local, q, half), 0.02f, out);
    float deepest = -1.f;
    for (const Contact& c : out) deepest = std::max(deepest, c.depth);
    if (std::abs(deepest - deepestCorner) > 2e-3f) {
      ++underReported;
      ADD_FAILURE() << "box " << i << ": deepest corner " << deepestCorner << " m, deepest contact " << deepest << " m (" << out.size() << " contacts)";
    }
  }
  EXPECT_EQ(underReported, 0);
}

TEST(TerrainContacts, CapsuleLyingFlatTouchesAtBothEnds) {
  const auto holder = flatTerrain();
  Terrain& terrain = *holder;
  std::vector<Contact> contacts;
  const Quatf lying(Eigen::AngleAxisf(float(M_PI / 2), Vec3f::UnitY()));  // core (local z) along X
  terrainContacts(terrain, capsuleAt(Vec3d(12.2, 4.0 + 0.3 - 0.02, 9.7), lying, 1.0f, 0.3f), 0.f, contacts);
  ASSERT_GE(contacts.size(), 2u);
  bool left = false, right = false;
  for (const Contact& c : contacts) {
    EXPECT_NEAR(c.depth, 0.02f, 1e-4f);
    left |= std::abs(c.position.x() - 11.2) < 1e-4;
    right |= std::abs(c.position.x() - 13.2) < 1e-4;
  }
  EXPECT_TRUE(left && right);
}

TEST(TerrainContacts, ConvexHullAgreesWithTheEquivalentBox) {
  const auto holder = flatTerrain();
  Terrain& terrain = *holder;
  const std::vector<Vec3f> pts = {{-0.4f, -0.3f, -0.2f}, {0.4f, -0.3f, -0.2f}, {-0.4f, 0.3f, -0.2f}, {0.4f, 0.3f, -0.2f},
                                  {-0.4f, -0.3f, 0.2f},  {0.4f, -0.3f, 0.2f},  {-0.4f, 0.3f, 0.2f},  {0.4f, 0.3f, 0.2f},
                                  {0.f, 0.f, 0.f}};
  const Placed hull{QueryShape::hull(pts.data(), uint32_t(pts.size())), {Vec3d(5.5, 4.25, 6.5), Quatf::Identity()}};
  EXPECT_NEAR(hull.shape.volume(), 0.8f * 0.6f * 0.4f, 1e-5f);
  std::vector<Contact> h, b;
  terrainContacts(terrain, hull, 0.f, h);
  terrainContacts(terrain, boxAt(Vec3d(5.5, 4.25, 6.5), Quatf::Identity(), Vec3f(0.4f, 0.3f, 0.2f)), 0.f, b);
  ASSERT_FALSE(h.empty());
  ASSERT_EQ(h.size(), b.size());
  for (size_t i = 0; i < h.size(); ++i) {
    EXPECT_NEAR(h[i].depth, b[i].depth, 1e-4f);
    EXPECT_NEAR(h[i].depth, 0.05f, 1e-4f);
  }
  EXPECT_THROW(terrainContacts(terrain, Placed{QueryShape::hull(pts.data(), 3), {}}, 0.f, h), InvalidInput);
}

TEST(TerrainContacts, WaterGivesSubmergedVolumeForBuoyancy) {
  Terrain terrain({32, 16, 32}, 1.f);
  terrain.fillBox({0, 0, 0}, {31, 3, 31}, Voxel::make(7));
  terrain.fillBox({0, 4, 0}, {31, 7, 31}, Voxel::make(kMaterialWater));  // water surface at y = 8
  WaterContact w;
  // Box with half its height under the surface.
  const Placed box = boxAt(Vec3d(10, 8, 10), Quatf::Identity(), Vec3f(1, 0.5f, 1));
  ASSERT_TRUE(terrainWaterContact(terrain, box, w));
  EXPECT_NEAR(w.submergedVolume, 2.0, 1e-4);
  EXPECT_NEAR(w.submergedFraction, 0.5f, 1e-5f);
  EXPECT_NEAR(w.centreOfBuoyancy.y(), 7.75, 1e-4);
  // Fully submerged sphere: the whole volume.
  ASSERT_TRUE(terrainWaterContact(terrain, sphereAt(Vec3d(10, 6, 10), 0.7f), w));
  EXPECT_NEAR(w.submergedVolume, 4.0 / 3.0 * M_PI * 0.343, 1e-3);
  EXPECT_NEAR(w.submergedFraction, 1.f, 1e-6f);
  // Partly filled water cells (occupancy 51/255 = 0.2 of a cell): water ends at y = 7.2.
  terrain.fillBox({0, 7, 0}, {31, 7, 31}, Voxel::make(kMaterialWater, 51));
  const Placed low = boxAt(Vec3d(10, 7.4, 10), Quatf::Identity(), Vec3f(1, 0.5f, 1));
  ASSERT_TRUE(terrainWaterContact(terrain, low, w));
  EXPECT_NEAR(w.submergedVolume, 4.0 * 0.3, 1e-4);  // from y = 6.9 to 7.2
  EXPECT_FALSE(terrainWaterContact(terrain, box, w));  // box bottom 7.5 is above the water
  // In the air above the water: nothing.
  EXPECT_FALSE(terrainWaterContact(terrain, sphereAt(Vec3d(10, 13, 10), 0.5f), w));
}

// The water sums voxel by voxel, as a reference reading every voxel through VoxelTerrain::get
// (terrainWaterContact reads a chunk layer at a time and skips chunks without water): the same
// bits, on terrains whose size is no multiple of a chunk, with water of any fill, solid and air
// mixed in, and boxes across chunk borders and past the terrain's edges.
TEST(TerrainContacts, WaterSumsEqualAVoxelByVoxelReference) {
  std::mt19937 rng(20261128);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  int compared = 0, wet = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const Int3 size{9 + int(rng() % 22), 5 + int(rng() % 14), 9 + int(rng() % 22)};
    const float vs = trial % 3 == 0 ? 0.5f : 1.f;
    Terrain terrain(size, vs);
    // Water up to a level, some of it partly filled, solid lumps and air pockets through it.
    const int level = 1 + int(rng() % uint32_t(size.y - 1));
    terrain.fillBox({0, 0, 0}, {size.x - 1, level - 1, size.z - 1}, Voxel::make(kMaterialWater));
    for (int k = 0; k < 200; ++k) {
      const Int3 v{int(rng() % uint32_t(size.x)), int(rng() % uint32_t(size.y)), int(rng() % uint32_t(size.z))};
      const uint32_t kind = rng() % 4;
      const Voxel voxel = kind == 0 ? Voxel::make(kMaterialWater, uint8_t(1 + rng() % 255))
                        : kind == 1 ? Voxel::make(kMaterialFirstSolid)
                        : kind == 2 ? Voxel::make(kMaterialWater) : Voxel{};
      terrain.fillBox(v, v, voxel);
    }
    for (int q = 0; q < 40; ++q) {
      // Axis-aligned boxes (terrain placed at the origin): the shape's local box is exactly
      // centre -+ half, which the reference recomputes.
      const Vec3f half(0.2f + 6.f * unit(rng), 0.2f + 4.f * unit(rng), 0.2f + 6.f * unit(rng));
      const Vec3f centre(-3.f + (float(size.x) * vs + 6.f) * unit(rng), -2.f + (float(size.y) * vs + 4.f) * unit(rng),
                         -3.f + (float(size.z) * vs + 6.f) * unit(rng));
      const Placed box = boxAt(centre.cast<double>(), Quatf::Identity(), half);
      WaterContact got;
      const bool hit = terrainWaterContact(terrain, box, got);
      const Aabb b = Aabb::fromCenterHalf(centre, half);
      int lo[3], hi[3];
      const int n[3] = {size.x, size.y, size.z};
      for (int i = 0; i < 3; ++i) {
        lo[i] = int(std::clamp(std::floor(double(b.min[i]) / vs), 0.0, double(n[i] - 1)));
        hi[i] = int(std::clamp(std::floor(double(b.max[i]) / vs), 0.0, double(n[i] - 1)));
      }
      double volume = 0;
      Vec3d moment = Vec3d::Zero();
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int z = lo[2]; z <= hi[2]; ++z)
          for (int x = lo[0]; x <= hi[0]; ++x) {
            const Voxel v = terrain.voxels().get({x, y, z});
            if (!v.isWater()) continue;
            const Vec3f cellMin(float(x) * vs, float(y) * vs, float(z) * vs);
            const Vec3f cellMax(cellMin.x() + vs, cellMin.y() + vs * float(v.occupancy) / 255.f, cellMin.z() + vs);
            const Vec3f omin = cellMin.cwiseMax(b.min), omax = cellMax.cwiseMin(b.max);
            if ((omin.array() >= omax.array()).any()) continue;
            const double ov = double((omax - omin).prod());
            volume += ov;
            moment += ov * ((omin + omax) * 0.5f).cast<double>();
          }
      ++compared;
      // (the terrain's own water test can end the query before the voxels: only when none overlap)
      ASSERT_EQ(hit, volume > 0) << "trial " << trial << " query " << q;
      if (!hit) continue;
      ++wet;
      EXPECT_EQ(got.submergedVolume, volume * (double(box.shape.volume()) / double(b.volume()))) << "trial " << trial << " query " << q;
      // (the terrain sits at the origin: the centre is the local one, in float)
      EXPECT_EQ(got.centreOfBuoyancy.cast<float>(), Vec3f((moment / volume).cast<float>())) << "trial " << trial << " query " << q;
    }
  }
  EXPECT_EQ(compared, 12 * 40);
  EXPECT_GT(wet, 12 * 10);  // most boxes meet water: the comparison is not of empty sums
}

TEST(TerrainContacts, RejectsInvalidShapes) {
  const auto holder = flatTerrain();
  Terrain& terrain = *holder;
  std::vector<Contact> contacts;
  EXPECT_THROW(terrainContacts(terrain, sphereAt(Vec3d(NAN, 0, 0), 1.f), 0.f, contacts), InvalidInput);
  EXPECT_THROW(terrainContacts(terrain, sphereAt(Vec3d(0, 0, 0), -1.f), 0.f, contacts), InvalidInput);
  EXPECT_THROW(terrainContacts(terrain, boxAt(Vec3d(0, 0, 0), Quatf(2, 0, 0, 0), Vec3f(1, 1, 1)), 0.f, contacts),
               InvalidInput);
  EXPECT_THROW(terrainContacts(terrain, sphereAt(Vec3d(0, 0, 0), 1.f), NAN, contacts), InvalidInput);
}

// The world spreads one query's candidate triangles over several jobs; whatever the cut, the
// joined pieces must give exactly the contacts of the whole query (the state hash depends on it).
TEST(TerrainContactPlan, PiecesOnAnyCutEqualTheWholeQuery) {
  const RigidTransform place{Vec3d(2.0e6, -3.0e5, 7.0e6), Quatf(Eigen::AngleAxisf(0.3f, Vec3f(0.2f, 1, 0.4f).normalized()))};
  Terrain terrain({48, 24, 48}, 0.5f, place);
  terrain.edit({0, 0, 0}, {47, 23, 47}, [](VoxelTerrain& v) { generateRandomTerrain(v, 77, 0.06f); });
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const std::vector<Vec3f> hullPoints = {{-0.6f, -0.2f, -0.3f}, {0.7f, -0.3f, -0.2f}, {0.f, 0.5f, -0.3f},
                                         {0.1f, 0.f, 0.6f},     {-0.3f, 0.3f, 0.4f},  {0.4f, 0.4f, 0.1f}};
  TerrainContactPlan plan;
  std::vector<Contact> want, got;
  std::vector<Contact> pieceContacts;
  std::vector<Vec3f> pieceNormals, normals;
  uint32_t planned = 0, cuts = 0;
  for (int q = 0; q < 400; ++q) {
    const float size = 0.2f + 5.8f * u(rng) * u(rng);  // mostly small, some spanning chunks
    QueryShape shape;
    switch (q % 4) {
      case 0: shape = QueryShape::sphere(size * 0.5f); break;
      case 1: shape = QueryShape::box(Vec3f(size * 0.5f, size * (0.05f + 0.45f * u(rng)), size * 0.3f)); break;
      case 2: shape = QueryShape::capsule(size * 0.2f, size * 0.4f); break;
      default: shape = QueryShape::hull(hullPoints.data(), uint32_t(hullPoints.size())); break;
    }
    const Vec3f local(u(rng) * 24.f, u(rng) * 12.f, u(rng) * 24.f);
    const RigidTransform pose{place.pointToWorld(local), Quatf(Eigen::AngleAxisf(6.f * u(rng), Vec3f(u(rng), u(rng), 1).normalized()))};
    const float spec = 0.05f * u(rng);
    want.clear();
    terrainContacts(terrain, shape, pose, spec, want);  // fills the cache for the plan
    ASSERT_TRUE(plan.plan(terrain, shape, pose, spec)) << q;
    const uint32_t n = plan.triangleCount();
    planned += n > 0;
    got.clear();
    normals.clear();
    for (uint32_t begin = 0; begin < n;) {
      const uint32_t end = std::min(n, begin + 1 + uint32_t(u(rng) * 6.f));
      pieceContacts.clear();
      pieceNormals.clear();
      plan.contactsOfTriangles(begin, end, pieceContacts, pieceNormals);
      ASSERT_EQ(pieceContacts.size(), pieceNormals.size());
      got.insert(got.end(), pieceContacts.begin(), pieceContacts.end());
      normals.insert(normals.end(), pieceNormals.begin(), pieceNormals.end());
      begin = end;
      ++cuts;
    }
    finishTerrainContacts(got, 0, normals);
    ASSERT_EQ(got.size(), want.size()) << q;
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].position, want[i].position) << q << " contact " << i;
      EXPECT_EQ(got[i].normal, want[i].normal) << q;
      EXPECT_EQ(got[i].depth, want[i].depth) << q;
      EXPECT_EQ(got[i].featureB, want[i].featureB) << q;
      EXPECT_EQ(got[i].material, want[i].material) << q;
    }
  }
  EXPECT_GT(planned, 150u);
  EXPECT_GT(cuts, 1000u);
  EXPECT_THROW(plan.contactsOfTriangles(0, plan.triangleCount() + 1, got, normals), InvalidInput);
}

TEST(TerrainContactPlan, RefusesChunksNotYetMeshed) {
  const auto holder = flatTerrain();
  Terrain& terrain = *holder;
  const Placed box = boxAt(Vec3d(10.3, 4.45, 10.4), Quatf::Identity(), Vec3f(0.5f, 0.5f, 0.5f));
  TerrainContactPlan plan;
  EXPECT_FALSE(plan.plan(terrain, box.shape, box.pose, 0.f));  // nothing meshed yet
  EXPECT_EQ(plan.triangleCount(), 0u);
  std::vector<Contact> contacts;
  ASSERT_GE(terrainContacts(terrain, box, 0.f, contacts), 4u);
  ASSERT_TRUE(plan.plan(terrain, box.shape, box.pose, 0.f));
  EXPECT_GT(plan.triangleCount(), 0u);
  EXPECT_THROW(plan.plan(terrain, box.shape, box.pose, -1.f), InvalidInput);
}

}  // namespace
}  // namespace bw
