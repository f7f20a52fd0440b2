#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <limits>
#include <random>
#include <vector>

#include "collision/content/terrain_generator.h"
#include "collision/terrain/chunk_mesher.h"
#include "collision/terrain/loose_kd_tree.h"

namespace bw {
namespace {

/// A mesh with 32-bit indices built by the test.
struct SoupMesh {
  std::vector<Vec3f> vertices;
  std::vector<uint32_t> indices;
  TriangleMeshView view() const {
    return {vertices.data(), nullptr, indices.data(), uint32_t(vertices.size()), uint32_t(indices.size() / 3)};
  }
};

SoupMesh randomSoup(uint32_t seed, int count, float extent) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(0.f, extent), size(-1.f, 1.f);
  SoupMesh m;
  for (int i = 0; i < count; ++i) {
    const Vec3f c(pos(rng), pos(rng), pos(rng));
    const float s = (rng() % 10 == 0) ? extent * 0.3f : 0.5f;  // some long triangles
    for (int k = 0; k < 3; ++k) {
      m.vertices.push_back(c + s * Vec3f(size(rng), size(rng), size(rng)));
      m.indices.push_back(uint32_t(m.vertices.size() - 1));
    }
  }
  // Degenerate triangles: a point and a segment.
  m.vertices.push_back(Vec3f(1, 1, 1));
  m.indices.insert(m.indices.end(), {uint32_t(m.vertices.size() - 1), uint32_t(m.vertices.size() - 1), uint32_t(m.vertices.size() - 1)});
  m.vertices.push_back(Vec3f(2, 1, 1));
  m.indices.insert(m.indices.end(), {uint32_t(m.vertices.size() - 2), uint32_t(m.vertices.size() - 1), uint32_t(m.vertices.size() - 1)});
  return m;
}

/// All chunk meshes of a random terrain merged into one mesh in terrain coordinates.
SoupMesh terrainMesh(uint32_t seed) {
  VoxelTerrain t({32, 16, 32});
  generateRandomTerrain(t, seed, 0.02f);
  SoupMesh m;
  ChunkNeighbourhood n;
  ChunkMesh chunk;
  for (int cy = 0; cy < 2; ++cy)
    for (int cz = 0; cz < 4; ++cz)
      for (int cx = 0; cx < 4; ++cx) {
        t.gatherNeighbourhood({cx, cy, cz}, n);
        meshChunk(n, 1.f, chunk);
        const uint32_t base = uint32_t(m.vertices.size());
        for (uint32_t v = 0; v < chunk.vertices.size(); ++v) m.vertices.push_back(chunk.vertex(v) + Vec3f(float(cx * 8), float(cy * 8), float(cz * 8)));
        for (uint16_t i : chunk.indices) m.indices.push_back(base + i);
      }
  return m;
}

std::vector<uint32_t> bruteAabb(const TriangleMeshView& m, const Aabb& box) {
  std::vector<uint32_t> out;
  for (uint32_t t = 0; t < m.triangleCount; ++t) {
    Vec3f a, b, c;
    m.corners(t, a, b, c);
    if (Aabb{a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c)}.overlaps(box)) out.push_back(t);
  }
  return out;
}

bool bruteRay(const TriangleMeshView& m, const Ray& ray, float& best) {
  const WatertightRay wr = WatertightRay::make(ray.origin, ray.dir);
  bool found = false;
  best = ray.maxT;
  for (uint32_t t = 0; t < m.triangleCount; ++t) {
    Vec3f a, b, c;
    m.corners(t, a, b, c);
    float th;
    if (wr.intersect(a, b, c, 0.f, best, th) && (!found || th < best)) {
      best = th;
      found = true;
    }
  }
  return found;
}

void checkAabbQueries(const TriangleMeshView& m, const LooseKdTree& tree, uint32_t seed, float extent) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-0.1f * extent, 1.1f * extent), size(0.f, 0.3f * extent);
  size_t reported = 0;
  for (int q = 0; q < 400; ++q) {
    const Vec3f lo(pos(rng), pos(rng), pos(rng));
    const Aabb box{lo, lo + Vec3f(size(rng), size(rng), size(rng))};
    std::vector<uint32_t> got;
    tree.queryAabb(m, box, [&](uint32_t t) { got.push_back(t); });
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, bruteAabb(m, box)) << "query " << q;
    reported += got.size();
  }
  EXPECT_GT(reported, 100u);
}

void checkRay(const TriangleMeshView& m, const LooseKdTree& tree, const Ray& ray, int& hits) {
  float want;
  const bool wantHit = bruteRay(m, ray, want);
  KdRayHit hit{};
  const bool gotHit = tree.raycastClosest(m, ray, hit);
  ASSERT_EQ(gotHit, wantHit) << "origin " << ray.origin.transpose() << " dir " << ray.dir.transpose();
  if (gotHit) {
    ASSERT_EQ(hit.t, want) << "origin " << ray.origin.transpose() << " dir " << ray.dir.transpose();
    ++hits;
  }
}

void checkRandomRays(const TriangleMeshView& m, const LooseKdTree& tree, uint32_t seed, float extent) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-0.2f * extent, 1.2f * extent), dir(-1.f, 1.f);
  int hits = 0;
  for (int q = 0; q < 600; ++q) {
    const Vec3f o(pos(rng), pos(rng), pos(rng));
    Vec3f d(dir(rng), dir(rng), dir(rng));
    if (q % 4 == 0) d = Vec3f::Zero(), d[q / 4 % 3] = (q % 8 == 0) ? 1.f : -1.f;  // axis-parallel
    if (d.squaredNorm() == 0.f) d = Vec3f(0, -1, 0);
    const float maxT = q % 5 == 0 ? extent * 0.2f : std::numeric_limits<float>::infinity();
    checkRay(m, tree, Ray::make(o, d, maxT), hits);
  }
  EXPECT_GT(hits, 50);
}

TEST(LooseKdTree, NodeIsTwelveBytesAndLeafTagIsTheFourthAxis) {
  EXPECT_EQ(sizeof(KdNode), 12u);
  KdNode leaf{5, 6, (2u << 2) | KdNode::kLeafAxis};
  EXPECT_EQ(leaf.axis(), 3u);
  EXPECT_EQ(leaf.payload(), 2u);
  KdNode branch{0, 0, ((1u << 30) - 1) << 2 | 2u};
  EXPECT_EQ(branch.axis(), 2u);
  EXPECT_EQ(branch.payload(), (1u << 30) - 1);
}

TEST(LooseKdTree, AabbAndRayQueriesMatchBruteForceOnTriangleSoups) {
  KdTreeBuilder builder;
  for (uint32_t seed : {1u, 2u}) {
    const SoupMesh m = randomSoup(seed, 3000, 50.f);
    LooseKdTree tree;
    tree.build(m.view(), builder);
    ASSERT_EQ(tree.validate(m.view()), "");
    checkAabbQueries(m.view(), tree, seed + 10, 50.f);
    checkRandomRays(m.view(), tree, seed + 20, 50.f);
  }
}

TEST(LooseKdTree, AabbAndRayQueriesMatchBruteForceOnTerrainMeshes) {
  KdTreeBuilder builder;
  for (uint32_t seed : {5u, 6u}) {
    const SoupMesh m = terrainMesh(seed);
    LooseKdTree tree;
    tree.build(m.view(), builder);
    ASSERT_EQ(tree.validate(m.view()), "");
    ASSERT_GT(m.view().triangleCount, 2000u);
    checkAabbQueries(m.view(), tree, seed + 10, 32.f);
    checkRandomRays(m.view(), tree, seed + 20, 32.f);
  }
}

TEST(LooseKdTree, AxisParallelAndGrazingRaysOnLatticeLinesMatchBruteForce) {
  // Rays from lattice points along lattice lines run exactly in face planes and along edges,
  // where triangles are hit edge-on and the split planes coincide with the ray.
  const SoupMesh m = terrainMesh(7);
  KdTreeBuilder builder;
  LooseKdTree tree;
  tree.build(m.view(), builder);
  int hits = 0;
  const Vec3f dirs[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int y = 0; y <= 16; y += 2)
    for (int z = 0; z <= 32; z += 3)
      for (int x = 0; x <= 32; x += 3)
        for (const Vec3f& d : dirs) checkRay(m.view(), tree, Ray::make(Vec3f(float(x), float(y), float(z)), d), hits);
  // Grazing diagonals inside horizontal planes and through lattice corners.
  for (int y = 0; y <= 16; ++y)
    for (int k = 0; k <= 32; k += 4) {
      checkRay(m.view(), tree, Ray::make(Vec3f(-1.f, float(y), float(k)), Vec3f(1.f, 0.f, 1.f)), hits);
      checkRay(m.view(), tree, Ray::make(Vec3f(float(k), float(y) + 0.5f, -1.f), Vec3f(0.f, -1.f, 1.f)), hits);
      checkRay(m.view(), tree, Ray::make(Vec3f(float(k), 20.f, float(k)), Vec3f(1e-30f, -1.f, 0.f)), hits);  // denormal-ish x
    }
  EXPECT_GT(hits, 300);
}

TEST(LooseKdTree, RaysAimedExactlyAtVerticesAndEdgesFromNearAndFar) {
  // Rays aimed exactly at a vertex or an edge midpoint hit at a point lying on split planes,
  // where the rounding of (plane - origin) / dir decides whether a child is visited. Without
  // the plane padding in the traversal this finds misses (checked: a few per thousand rays).
  const HeightfieldMesh hf = makeHeightfieldMesh(40, 0.37f, 3.f, 3);
  const TriangleMeshView view = hf.view();
  KdTreeBuilder builder;
  LooseKdTree tree;
  tree.build(view, builder);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  int hits = 0;
  for (float far : {1.f, 100.f, 10000.f}) {
    for (int q = 0; q < 3000; ++q) {
      const uint32_t vi = rng() % view.vertexCount;
      Vec3f target = hf.vertices[vi];
      if (rng() % 2) target = 0.5f * (target + hf.vertices[std::min<uint32_t>(vi + 1, view.vertexCount - 1)]);
      Vec3f o = target + far * Vec3f(u(rng), std::abs(u(rng)) + 0.05f, u(rng));
      if (rng() % 3 == 0) o.y() = target.y();  // horizontal, grazing the surface
      const Vec3f d = target - o;
      if (d.squaredNorm() == 0.f) continue;
      checkRay(view, tree, Ray::make(o, d), hits);
    }
  }
  EXPECT_GT(hits, 8000);
}

TEST(LooseKdTree, DownwardRaysOnSharedQuadEdgesNeverFallThrough) {
  // A flat floor of quads; rays straight down through every lattice point and edge midpoint
  // must hit: the watertight test counts shared edges and corners as hits.
  VoxelTerrain t({16, 8, 16});
  t.fillBox({0, 0, 0}, {15, 2, 15}, Voxel::make(kMaterialFirstSolid));
  ChunkNeighbourhood n;
  ChunkMesh mesh;
  t.gatherNeighbourhood({0, 0, 0}, n);
  meshChunk(n, 0.7f, mesh);
  KdTreeBuilder builder;
  LooseKdTree tree;
  tree.build(mesh.view(), builder);
  for (int z = 0; z <= 16; ++z)
    for (int x = 0; x <= 16; ++x) {
      const Vec3f o(float(x) * 0.35f, 100.f, float(z) * 0.35f);
      KdRayHit hit{};
      ASSERT_TRUE(tree.raycastClosest(mesh.view(), Ray::make(o, Vec3f(0, -1, 0)), hit)) << x << "," << z;
      ASSERT_NEAR(100.f - hit.t, 3.f * 0.7f, 1e-4f);
    }
}

TEST(LooseKdTree, EarlyExitVisitsFewerNodesThanTheWholeTree) {
  const SoupMesh m = terrainMesh(8);
  KdTreeBuilder builder;
  LooseKdTree tree;
  tree.build(m.view(), builder);
  // A long ray across the terrain just above the ground hits a bump early.
  uint32_t visited = 0;
  KdRayHit hit{};
  ASSERT_TRUE(tree.raycastClosestCounted(m.view(), Ray::make(Vec3f(16, 30, 16), Vec3f(0.01f, -1, 0.02f)), hit, visited));
  EXPECT_LT(visited, tree.nodes().size() / 10);
}

/// A heightfield of n x n quads moved by `offset` (wide: its heights span a few metres).
SoupMesh wideHeightfield(uint32_t n, float amplitude, uint32_t seed, const Vec3f& offset) {
  const HeightfieldMesh h = makeHeightfieldMesh(n, 1.f, amplitude, seed);
  SoupMesh m;
  for (const Vec3f& v : h.vertices) m.vertices.push_back(v + offset);
  m.indices = h.indices;
  return m;
}

TEST(LooseKdTree, HeightBoundsOnWideMeshesKeepEveryAnswerAndSkipTheNodesARayPassesOver) {
  KdTreeBuilder builder;
  const Vec3f offsets[] = {Vec3f::Zero(), Vec3f(3000.f, -250.f, -4000.f)};
  for (uint32_t seed : {3u, 4u}) {
    for (const Vec3f& offset : offsets) {
      const SoupMesh m = wideHeightfield(96, 10.f, seed, offset);  // 18,432 triangles, heights within +-10 m
      LooseKdTree bounded, plain;
      bounded.build(m.view(), builder);
      plain.build(m.view(), builder, KdHeightBoundsMode::Off);
      ASSERT_TRUE(bounded.hasHeightBounds());
      ASSERT_EQ(bounded.heightAxis(), 1);
      ASSERT_FALSE(plain.hasHeightBounds());
      ASSERT_EQ(bounded.validate(m.view()), "");
      EXPECT_EQ(bounded.bytes(), plain.bytes() + plain.nodes().size() * sizeof(KdHeightBounds));

      // Rays from 1-30 m above the surface, down with a slant (the benchmark's); rays from 1-10 m
      // above the ground below them at a shallow angle, over valleys and hills before they land
      // (those count nodes); then any direction from anywhere around the field.
      std::mt19937 rng(seed * 7 + uint32_t(offset.x()));
      std::uniform_real_distribution<float> xz(-4.f, 100.f), up(1.f, 30.f), low(1.f, 10.f), slant(-0.6f, 0.6f),
          shallow(0.5f, 2.f), y(-8.f, 8.f), d(-1.f, 1.f);
      uint64_t visitedBounded = 0, visitedPlain = 0;
      int hits = 0;
      for (int q = 0; q < 1200; ++q) {
        Vec3f o, dir;
        if (q < 400) {
          o = Vec3f(xz(rng), 10.f + up(rng), xz(rng));
          dir = Vec3f(slant(rng), -1.f, slant(rng));
        } else if (q < 800) {
          o = Vec3f(xz(rng), 0.f, xz(rng));
          o.y() = heightfieldHeight(o.x(), o.z(), 10.f, seed) + low(rng);
          const float sx = o.x() < 48.f ? 1.f : -1.f, sz = o.z() < 48.f ? 1.f : -1.f;  // towards the middle
          dir = Vec3f(sx * shallow(rng), -1.f, sz * shallow(rng));
        } else {
          o = Vec3f(xz(rng), y(rng), xz(rng));
          dir = Vec3f(d(rng), d(rng) * (q % 3 == 0 ? 0.f : 1.f), d(rng));  // a third level with the field
          if (q % 7 == 0) dir = Vec3f(0, q % 2 ? 1.f : -1.f, 0);
          if (dir.squaredNorm() == 0.f) dir = Vec3f(1, 0, 0);
        }
        const Ray ray = Ray::make(o + offset, dir, q % 5 == 0 ? 20.f : 300.f);
        float want;
        const bool wantHit = bruteRay(m.view(), ray, want);
        KdRayHit got{}, gotPlain{};
        uint32_t vb = 0, vp = 0;
        ASSERT_EQ(bounded.raycastClosestCounted(m.view(), ray, got, vb), wantHit) << "ray " << q;
        ASSERT_EQ(plain.raycastClosestCounted(m.view(), ray, gotPlain, vp), wantHit) << "ray " << q;
        if (wantHit) {
          ASSERT_EQ(got.t, want) << "ray " << q;
          ASSERT_EQ(got.triangle, gotPlain.triangle) << "ray " << q;
          ++hits;
        }
        if (q >= 400 && q < 800 && q % 5 != 0) visitedBounded += vb, visitedPlain += vp;
      }
      EXPECT_GT(hits, 500);
      // The shallow rays pass over metres of lower ground before they land: the bounds must cut
      // the nodes they visit by a third or more (about half, measured).
      EXPECT_LT(visitedBounded * 3, visitedPlain * 2) << visitedBounded << " against " << visitedPlain;

      // Boxes from 0.2 to 20 m around the surface and above it: the same triangles as brute force.
      std::uniform_real_distribution<float> size(0.1f, 10.f), lift(-2.f, 12.f);
      size_t reported = 0;
      for (int q = 0; q < 300; ++q) {
        Vec3f c(xz(rng), 0.f, xz(rng));
        c.y() = heightfieldHeight(c.x(), c.z(), 10.f, seed) + lift(rng);
        const Vec3f half(size(rng), size(rng) * 0.3f, size(rng));
        const Aabb box{c + offset - half, c + offset + half};
        std::vector<uint32_t> got;
        bounded.queryAabb(m.view(), box, [&](uint32_t t) { got.push_back(t); });
        std::sort(got.begin(), got.end());
        ASSERT_EQ(got, bruteAabb(m.view(), box)) << "box " << q;
        reported += got.size();
      }
      EXPECT_GT(reported, 1000u);
    }
  }
}

TEST(LooseKdTree, NoHeightBoundsOnSmallOrBoxyMeshes) {
  KdTreeBuilder builder;
  LooseKdTree tree;
  const SoupMesh small = wideHeightfield(40, 3.f, 1, Vec3f::Zero());  // 3200 triangles
  tree.build(small.view(), builder);
  EXPECT_FALSE(tree.hasHeightBounds());
  const SoupMesh boxy = randomSoup(3, 6000, 50.f);
  tree.build(boxy.view(), builder);
  EXPECT_FALSE(tree.hasHeightBounds());
  const SoupMesh wide = wideHeightfield(48, 3.f, 1, Vec3f::Zero());  // 4608 triangles
  tree.build(wide.view(), builder);
  EXPECT_TRUE(tree.hasHeightBounds());
  tree.build(boxy.view(), builder);  // a rebuild drops them
  EXPECT_FALSE(tree.hasHeightBounds());
  EXPECT_EQ(tree.validate(boxy.view()), "");
}

TEST(LooseKdTree, DepthBoundedOnDegenerateInputs) {
  // Every triangle has the same midpoint: the mean split puts all on one side, the median
  // fallback must still split evenly and terminate.
  SoupMesh m;
  for (int i = 0; i < 5000; ++i) {
    const float s = 1.f + float(i);
    m.vertices.insert(m.vertices.end(), {Vec3f(-s, 0, 0), Vec3f(s, 0, 0), Vec3f(0, s, 0), Vec3f(0, -s, 0)});
    const uint32_t b = uint32_t(m.vertices.size() - 4);
    m.indices.insert(m.indices.end(), {b, b + 1, b + 2, b, b + 1, b + 3});
  }
  KdTreeBuilder builder;
  LooseKdTree tree;
  tree.build(m.view(), builder);
  EXPECT_EQ(tree.validate(m.view()), "");
  EXPECT_LE(tree.depth(), uint32_t(std::ceil(std::log(10000.0 / 2.0) / std::log(4.0 / 3.0))) + 2);
  checkAabbQueries(m.view(), tree, 3, 100.f);
}

TEST(LooseKdTree, EmptyAndTinyMeshes) {
  KdTreeBuilder builder;
  LooseKdTree tree;
  SoupMesh empty;
  tree.build(empty.view(), builder);
  EXPECT_EQ(tree.nodes().size(), 0u);
  KdRayHit hit{};
  EXPECT_FALSE(tree.raycastClosest(empty.view(), Ray::make(Vec3f::Zero(), Vec3f(1, 0, 0)), hit));
  int calls = 0;
  tree.queryAabb(empty.view(), {Vec3f::Constant(-1e9f), Vec3f::Constant(1e9f)}, [&](uint32_t) { ++calls; });
  EXPECT_EQ(calls, 0);
  SoupMesh one;
  one.vertices = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 0, 1)};
  one.indices = {0, 2, 1};
  tree.build(one.view(), builder);
  EXPECT_EQ(tree.nodes().size(), 1u);
  EXPECT_EQ(tree.validate(one.view()), "");
  ASSERT_TRUE(tree.raycastClosest(one.view(), Ray::make(Vec3f(0.2f, 5, 0.2f), Vec3f(0, -1, 0)), hit));
  EXPECT_FLOAT_EQ(hit.t, 5.f);
  // A ray lying in the triangle's plane is edge-on: no hit, and no NaN trouble.
  EXPECT_FALSE(tree.raycastClosest(one.view(), Ray::make(Vec3f(-1, 0, 0.2f), Vec3f(1, 0, 0)), hit));
}

}  // namespace
}  // namespace bw
