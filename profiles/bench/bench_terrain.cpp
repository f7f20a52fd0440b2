/// Voxel terrain benchmarks (issue 6, article 001): bitmask broadphase memory and AABB test
/// cost; loose kD tree vs Bullet's btBvhTriangleMeshShape (quantized and not) on the same
/// chunk meshes and on one ~1M-triangle heightfield, both sides in the same run; mesher and
/// cached terrain raycasts. Figures are Google Benchmark counters.
#include <BulletCollision/CollisionShapes/btHeightfieldTerrainShape.h>
#include <BulletCollision/NarrowPhaseCollision/btRaycastCallback.h>
#include <benchmark/benchmark.h>
#include <btBulletCollisionCommon.h>
#include <memory>
#include <random>
#include <vector>

#include "collision/content/terrain_generator.h"
#include "collision/terrain/chunk_mesher.h"
#include "collision/terrain/loose_kd_tree.h"
#include "collision/terrain/terrain.h"
#include "collision/terrain/terrain_queries.h"

namespace bw {
namespace {

// ---------------------------------------------------------------------------------------------
// Workloads (built once, shared by both sides of every comparison)

/// Rolling hills 1024 x 128 x 1024 voxels with lakes: the broadphase workload.
Terrain& hills() {
  static std::unique_ptr<Terrain> t = [] {
    auto p = std::make_unique<Terrain>(Int3{1024, 128, 1024}, 1.f);
    p->edit({0, 0, 0}, {1023, 127, 1023}, [](VoxelTerrain& v) { generateRollingHills(v, 11, 20, 60, 45); });
    return p;
  }();
  return *t;
}

/// Every non-empty chunk mesh of a 256 x 64 x 256 random terrain (caves, blobs, water).
const std::vector<ChunkMesh>& chunkMeshes() {
  static const std::vector<ChunkMesh> meshes = [] {
    VoxelTerrain t({256, 64, 256});
    generateRandomTerrain(t, 7, 0.01f);
    std::vector<ChunkMesh> out;
    ChunkNeighbourhood n;
    for (int cy = 0; cy < t.chunkGrid().y; ++cy)
      for (int cz = 0; cz < t.chunkGrid().z; ++cz)
        for (int cx = 0; cx < t.chunkGrid().x; ++cx) {
          t.gatherNeighbourhood({cx, cy, cz}, n);
          ChunkMesh m;
          meshChunk(n, 1.f, m);
          if (m.triangleCount()) out.push_back(std::move(m));
        }
    return out;
  }();
  return meshes;
}

/// Float copies of the chunk meshes' lattice vertices: Bullet reads float (or double) vertices only.
const std::vector<std::vector<Vec3f>>& chunkFloatVertices() {
  static const std::vector<std::vector<Vec3f>> out = [] {
    std::vector<std::vector<Vec3f>> v;
    for (const ChunkMesh& m : chunkMeshes()) {
      std::vector<Vec3f>& f = v.emplace_back();
      for (uint32_t i = 0; i < m.vertices.size(); ++i) f.push_back(m.vertex(i));
    }
    return v;
  }();
  return out;
}

/// The view Bullet gets of chunk mesh k: same indices, float vertices.
TriangleMeshView bulletView(size_t k) {
  TriangleMeshView v = chunkMeshes()[k].view();
  v.lattice = nullptr;
  v.vertices = chunkFloatVertices()[k].data();
  return v;
}

constexpr uint32_t kHeightfieldQuads = 707;  // 2 * 707^2 = 999,698 triangles
constexpr float kHeightfieldAmplitude = 40.f;
constexpr uint32_t kHeightfieldSeed = 5;

const HeightfieldMesh& heightfield() {
  static const HeightfieldMesh m = makeHeightfieldMesh(kHeightfieldQuads, 1.f, kHeightfieldAmplitude, kHeightfieldSeed);
  return m;
}

/// Vertices + indices (float vertices; the material byte of chunk meshes is counted by ChunkMesh::bytes).
size_t meshBytes(const TriangleMeshView& v) {
  return size_t(v.vertexCount) * sizeof(Vec3f) + size_t(v.triangleCount) * 3 * (v.indices16 ? 2 : 4);
}

/// Bullet's BVH triangle mesh over the same arrays (no copy).
struct BulletBvhMesh {
  btTriangleIndexVertexArray array;
  std::unique_ptr<btBvhTriangleMeshShape> shape;

  BulletBvhMesh(const TriangleMeshView& v, bool quantized) {
    btIndexedMesh im;
    im.m_numTriangles = int(v.triangleCount);
    im.m_triangleIndexBase = v.indices16 ? reinterpret_cast<const unsigned char*>(v.indices16)
                                         : reinterpret_cast<const unsigned char*>(v.indices32);
    im.m_triangleIndexStride = v.indices16 ? 6 : 12;
    im.m_numVertices = int(v.vertexCount);
    im.m_vertexBase = reinterpret_cast<const unsigned char*>(v.vertices);
    im.m_vertexStride = sizeof(Vec3f);
    im.m_indexType = v.indices16 ? PHY_SHORT : PHY_INTEGER;
    im.m_vertexType = PHY_FLOAT;
    array.addIndexedMesh(im, im.m_indexType);
    shape = std::make_unique<btBvhTriangleMeshShape>(&array, quantized, true);
  }
  /// Node storage of the BVH (Bullet's own serialized-size accounting: nodes + subtree headers).
  size_t treeBytes() const { return shape->getOptimizedBvh()->calculateSerializeBufferSize(); }
};

/// Closest hit through Bullet's BVH ray traversal.
struct BulletClosestHit : btTriangleRaycastCallback {
  int triangle = -1;
  BulletClosestHit(const btVector3& from, const btVector3& to) : btTriangleRaycastCallback(from, to) {}
  btScalar reportHit(const btVector3&, btScalar fraction, int, int triangleIndex) override {
    triangle = triangleIndex;
    return fraction;  // processTriangle only reports hits closer than m_hitFraction
  }
};

/// The same heights as Bullet holds a heightfield: btHeightfieldTerrainShape (float heights,
/// quads cut along the same diagonal: flipQuadEdges) with its ray accelerator (buildAccelerator:
/// min/max heights per 16 x 16 chunk, walked along the ray), the setup its docs advise for
/// raycasts on large heightfields. Its local origin is the middle of its bounds.
struct BulletHeightfield {
  std::vector<float> heights;  // (n + 1)^2, row by row along x
  std::unique_ptr<btHeightfieldTerrainShape> shape;
  btVector3 origin;  // where the shape's local origin lies in the mesh's frame
  BulletHeightfield(const std::vector<Vec3f>& vertices, uint32_t n) {
    float lo = vertices[0].y(), hi = lo;
    for (const Vec3f& v : vertices) {
      heights.push_back(v.y());
      lo = std::min(lo, v.y());
      hi = std::max(hi, v.y());
    }
    shape = std::make_unique<btHeightfieldTerrainShape>(int(n + 1), int(n + 1), heights.data(), lo, hi, 1, true);
    shape->buildAccelerator();
    origin = btVector3(float(n) * 0.5f, (lo + hi) * 0.5f, float(n) * 0.5f);  // spacing 1
  }
};

struct BulletCountTriangles : btTriangleCallback {
  uint64_t count = 0;
  void processTriangle(btVector3*, int, int) override { ++count; }
};

struct RaySample {
  Vec3f origin, dir;  // dir unit
  float length;
};

btVector3 bt(const Vec3f& v) { return btVector3(v.x(), v.y(), v.z()); }

// KdTreeNoHeightBounds: the same tree built without height bounds (what they bring, measured).
// btHeightfield: Bullet's heightfield shape over the same heights (BulletHeightfield).
enum Side { kKdTree = 0, kBtQuantized = 1, kBtNonQuantized = 2, kKdTreeNoHeightBounds = 3, kBtHeightfield = 4 };

// ---------------------------------------------------------------------------------------------
// Bitmask broadphase

void BM_BitmaskBroadphase_Memory_Hills1024(benchmark::State& state) {
  Terrain& t = hills();
  for (auto _ : state) benchmark::DoNotOptimize(t.broadphase().bytes());
  const double voxels = 1024.0 * 128.0 * 1024.0;
  const BitmaskBroadphase& bp = t.broadphase();
  state.counters["bytes_per_voxel"] = double(bp.bytes()) / voxels;
  state.counters["bits_per_voxel"] = 8.0 * double(bp.bytes()) / voxels;
  state.counters["worst_case_bits_per_voxel"] = 8.0 * double(sizeof(ChunkBitmask)) / kChunkVoxels;
  state.counters["chunks_with_entry"] = double(bp.entryCount());
  state.counters["chunks_masked"] = double(bp.maskedCount());
  state.counters["chunks_tagged_full"] = double(bp.entryCount() - bp.maskedCount());
  state.counters["voxel_storage_bytes_per_voxel"] = double(t.voxels().residentBytes()) / voxels;
}

void BM_BitmaskBroadphase_Memory_World4096(benchmark::State& state) {
  // A world-sized terrain (4096 x 256 x 4096 voxels): ground 12 voxels thick, 2 of water.
  for (auto _ : state) {
    auto t = std::make_unique<Terrain>(Int3{4096, 256, 4096}, 1.f);
    t->fillBox({0, 0, 0}, {4095, 11, 4095}, Voxel::make(kMaterialFirstSolid));
    t->fillBox({0, 12, 0}, {4095, 13, 4095}, Voxel::make(kMaterialWater));
    const double voxels = 4096.0 * 256.0 * 4096.0;
    state.counters["bytes_per_voxel"] = double(t->broadphase().bytes()) / voxels;
    state.counters["broadphase_MB"] = double(t->broadphase().bytes()) / 1e6;
    state.counters["voxel_storage_MB"] = double(t->voxels().residentBytes()) / 1e6;
    state.counters["chunks_masked"] = double(t->broadphase().maskedCount());
    state.counters["chunks_tagged_full"] = double(t->broadphase().entryCount() - t->broadphase().maskedCount());
  }
}

void BM_BitmaskBroadphase_AabbTest(benchmark::State& state) {
  Terrain& t = hills();
  const float maxSize = state.range(0) ? 32.f : 2.f;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> xz(0.f, 1000.f), y(15.f, 90.f), sz(0.25f, maxSize);
  std::vector<Aabb> boxes(4096);
  for (Aabb& b : boxes) {
    const Vec3f lo(xz(rng), y(rng), xz(rng));
    b = {lo, lo + Vec3f(sz(rng), sz(rng), sz(rng))};
  }
  size_t i = 0, solid = 0, water = 0;
  for (auto _ : state) {
    const TerrainOverlap o = t.overlapLocal(boxes[i++ & 4095]);
    solid += o.solid;
    water += o.water;
    benchmark::DoNotOptimize(o);
  }
  state.SetLabel(state.range(0) ? "large (0.25..32 voxels)" : "small (0.25..2 voxels)");
  state.counters["solid_fraction"] = double(solid) / double(state.iterations());
  state.counters["water_fraction"] = double(water) / double(state.iterations());
}

void BM_BitmaskBroadphase_RebuildChunk(benchmark::State& state) {
  Terrain& t = hills();
  BitmaskBroadphase bp(t.voxels().chunkGrid(), t.voxels().size());
  int i = 0;
  for (auto _ : state) {
    bp.rebuildChunk(t.voxels(), {i & 127, 3, (i >> 7) & 127});
    ++i;
  }
  state.SetItemsProcessed(state.iterations());
}

// ---------------------------------------------------------------------------------------------
// Mesher

void BM_Mesher_Chunk(benchmark::State& state) {
  Terrain& t = hills();
  ChunkNeighbourhood n;
  ChunkMesh m;
  int i = 0;
  uint64_t tris = 0;
  for (auto _ : state) {
    const Int3 c{i & 127, 4, (i >> 7) & 127};  // chunks around the hills' surface band
    t.voxels().gatherNeighbourhood(c, n);
    meshChunk(n, 1.f, m);
    tris += m.triangleCount();
    ++i;
  }
  state.counters["triangles_per_chunk"] = double(tris) / double(state.iterations());
  state.SetItemsProcessed(state.iterations());
}

// ---------------------------------------------------------------------------------------------
// kD tree vs Bullet: chunk meshes

void BM_ChunkMeshes_Build(benchmark::State& state, int side) {
  const std::vector<ChunkMesh>& meshes = chunkMeshes();
  // Mesh bytes each side needs: ours is the lattice mesh with materials, Bullet's the float
  // vertices it requires plus the same 16-bit indices.
  size_t tris = 0, mesh = 0;
  for (size_t k = 0; k < meshes.size(); ++k) {
    tris += meshes[k].triangleCount();
    mesh += side == kKdTree ? meshes[k].bytes() : meshBytes(bulletView(k));
  }
  size_t treeBytes = 0;
  KdTreeBuilder builder;
  LooseKdTree tree;
  for (auto _ : state) {
    treeBytes = 0;
    for (size_t k = 0; k < meshes.size(); ++k) {
      if (side == kKdTree) {
        tree.build(meshes[k].view(), builder);
        treeBytes += tree.bytes();
      } else {
        BulletBvhMesh b(bulletView(k), side == kBtQuantized);
        treeBytes += b.treeBytes();
      }
    }
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(meshes.size()));  // chunks per second
  state.counters["chunks"] = double(meshes.size());
  state.counters["triangles_per_chunk"] = double(tris) / double(meshes.size());
  state.counters["bytes_per_triangle"] = double(treeBytes) / double(tris);
  state.counters["bytes_per_triangle_with_mesh"] = double(treeBytes + mesh) / double(tris);
}

struct ChunkSides {
  std::vector<LooseKdTree> kd;
  std::vector<std::unique_ptr<BulletBvhMesh>> q, nq;
};
const ChunkSides& chunkSides() {
  static const ChunkSides s = [] {
    ChunkSides s;
    KdTreeBuilder b;
    for (size_t k = 0; k < chunkMeshes().size(); ++k) {
      s.kd.emplace_back().build(chunkMeshes()[k].view(), b);
      s.q.push_back(std::make_unique<BulletBvhMesh>(bulletView(k), true));
      s.nq.push_back(std::make_unique<BulletBvhMesh>(bulletView(k), false));
    }
    return s;
  }();
  return s;
}

void BM_ChunkMeshes_Raycast(benchmark::State& state, int side) {
  const std::vector<ChunkMesh>& meshes = chunkMeshes();
  const ChunkSides& sides = chunkSides();
  // Rays from above each chunk's box, downwards with a slant, through the chunk.
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.f, 8.f), s(-0.5f, 0.5f);
  std::vector<RaySample> rays(4096);
  for (RaySample& r : rays) r = {Vec3f(u(rng), 9.f, u(rng)), Vec3f(s(rng), -1.f, s(rng)).normalized(), 12.f};
  size_t i = 0, hits = 0;
  for (auto _ : state) {
    const size_t k = i % meshes.size();
    const RaySample& r = rays[i++ & 4095];
    if (side == kKdTree) {
      KdRayHit h;
      hits += sides.kd[k].raycastClosest(meshes[k].view(), Ray::make(r.origin, r.dir, r.length), h);
    } else {
      const BulletBvhMesh& b = side == kBtQuantized ? *sides.q[k] : *sides.nq[k];
      BulletClosestHit cb(bt(r.origin), bt(r.origin + r.dir * r.length));
      b.shape->performRaycast(&cb, cb.m_from, cb.m_to);
      hits += cb.triangle >= 0;
    }
  }
  state.counters["hit_fraction"] = double(hits) / double(state.iterations());
}

// ---------------------------------------------------------------------------------------------
// kD tree vs Bullet: one ~1M-triangle heightfield

void BM_Heightfield1M_Build(benchmark::State& state, int side) {
  const HeightfieldMesh& hf = heightfield();
  const TriangleMeshView v = hf.view();
  size_t treeBytes = 0;
  KdTreeBuilder builder;
  for (auto _ : state) {
    if (side == kKdTree || side == kKdTreeNoHeightBounds) {
      LooseKdTree tree;
      tree.build(v, builder, side == kKdTree ? KdHeightBoundsMode::Auto : KdHeightBoundsMode::Off);
      treeBytes = tree.bytes();
      state.counters["depth"] = double(tree.depth());
      state.counters["nodes_per_triangle"] = double(tree.nodes().size()) / double(v.triangleCount);
    } else {
      BulletBvhMesh b(v, side == kBtQuantized);
      treeBytes = b.treeBytes();
    }
  }
  state.counters["triangles"] = double(v.triangleCount);
  state.counters["bytes_per_triangle"] = double(treeBytes) / double(v.triangleCount);
  state.counters["bytes_per_triangle_with_mesh"] = double(treeBytes + meshBytes(v)) / double(v.triangleCount);
}

struct HeightfieldSides {
  LooseKdTree kd, kdPlain;  // with height bounds (the heightfield is wide) and without
  std::unique_ptr<BulletBvhMesh> q, nq;
  std::unique_ptr<BulletHeightfield> hf;
  std::vector<RaySample> rays;
  std::vector<Aabb> boxes;
  uint32_t disagreements = 0, heightfieldDisagreements = 0;
};
const HeightfieldSides& heightfieldSides() {
  static const HeightfieldSides s = [] {
    HeightfieldSides s;
    const HeightfieldMesh& hf = heightfield();
    KdTreeBuilder b;
    s.kd.build(hf.view(), b);
    s.kdPlain.build(hf.view(), b, KdHeightBoundsMode::Off);
    s.q = std::make_unique<BulletBvhMesh>(hf.view(), true);
    s.nq = std::make_unique<BulletBvhMesh>(hf.view(), false);
    s.hf = std::make_unique<BulletHeightfield>(hf.vertices, kHeightfieldQuads);
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> xz(5.f, float(kHeightfieldQuads) - 5.f), up(2.f, 30.f), sl(-0.6f, 0.6f);
    for (int i = 0; i < 4096; ++i) {
      const float x = xz(rng), z = xz(rng);
      const float h = heightfieldHeight(x, z, kHeightfieldAmplitude, kHeightfieldSeed);
      s.rays.push_back({Vec3f(x, h + up(rng), z), Vec3f(sl(rng), -1.f, sl(rng)).normalized(), 200.f});
      s.boxes.push_back(Aabb::fromCenterHalf(Vec3f(x, h, z), Vec3f::Constant(1.f)));  // 2 m box on the surface
    }
    // Both sides must find the same closest triangle, or the timing compares different work.
    for (const RaySample& r : s.rays) {
      KdRayHit h;
      const bool kd = s.kd.raycastClosest(hf.view(), Ray::make(r.origin, r.dir, r.length), h);
      BulletClosestHit cb(bt(r.origin), bt(r.origin + r.dir * r.length));
      s.q->shape->performRaycast(&cb, cb.m_from, cb.m_to);
      if (kd != (cb.triangle >= 0) || (kd && int(h.triangle) != cb.triangle)) ++s.disagreements;
      // The heightfield numbers its triangles its own way: compare where the hit lies.
      BulletClosestHit hcb(bt(r.origin) - s.hf->origin, bt(r.origin + r.dir * r.length) - s.hf->origin);
      s.hf->shape->performRaycast(&hcb, hcb.m_from, hcb.m_to);
      if (kd != (hcb.triangle >= 0) || (kd && std::abs(hcb.m_hitFraction * r.length - h.t) > 1e-3f)) ++s.heightfieldDisagreements;
    }
    return s;
  }();
  return s;
}

void BM_Heightfield1M_Raycast(benchmark::State& state, int side) {
  const HeightfieldSides& s = heightfieldSides();
  const TriangleMeshView v = heightfield().view();
  size_t i = 0, hits = 0;
  for (auto _ : state) {
    const RaySample& r = s.rays[i++ & 4095];
    if (side == kKdTree || side == kKdTreeNoHeightBounds) {
      KdRayHit h;
      hits += (side == kKdTree ? s.kd : s.kdPlain).raycastClosest(v, Ray::make(r.origin, r.dir, r.length), h);
    } else if (side == kBtHeightfield) {
      BulletClosestHit cb(bt(r.origin) - s.hf->origin, bt(r.origin + r.dir * r.length) - s.hf->origin);
      s.hf->shape->performRaycast(&cb, cb.m_from, cb.m_to);
      hits += cb.triangle >= 0;
    } else {
      BulletClosestHit cb(bt(r.origin), bt(r.origin + r.dir * r.length));
      (side == kBtQuantized ? s.q : s.nq)->shape->performRaycast(&cb, cb.m_from, cb.m_to);
      hits += cb.triangle >= 0;
    }
  }
  state.counters["hit_fraction"] = double(hits) / double(state.iterations());
  state.counters["closest_hit_disagreements"] =
      double(side == kBtHeightfield ? s.heightfieldDisagreements : s.disagreements);
  if (side == kKdTree || side == kKdTreeNoHeightBounds) {
    // Nodes visited per ray over the 4096 rays, counted outside the timed loop.
    uint64_t visited = 0;
    for (const RaySample& r : s.rays) {
      KdRayHit h;
      uint32_t n = 0;
      (side == kKdTree ? s.kd : s.kdPlain).raycastClosestCounted(v, Ray::make(r.origin, r.dir, r.length), h, n);
      visited += n;
    }
    state.counters["nodes_visited"] = double(visited) / double(s.rays.size());
  }
}

void BM_Heightfield1M_AabbQuery2m(benchmark::State& state, int side) {
  const HeightfieldSides& s = heightfieldSides();
  const TriangleMeshView v = heightfield().view();
  size_t i = 0;
  uint64_t found = 0;
  for (auto _ : state) {
    const Aabb& b = s.boxes[i++ & 4095];
    if (side == kKdTree) {
      s.kd.queryAabb(v, b, [&](uint32_t) { ++found; });
    } else {
      BulletCountTriangles cb;
      (side == kBtQuantized ? s.q : s.nq)->shape->processAllTriangles(&cb, bt(b.min), bt(b.max));
      found += cb.count;
    }
  }
  state.counters["triangles_per_query"] = double(found) / double(state.iterations());
}

// ---------------------------------------------------------------------------------------------
// Terrain raycasts through the lazy cache

void BM_TerrainRaycast(benchmark::State& state) {
  Terrain& t = hills();
  t.cache().setBudget(size_t(state.range(0)) << 20);
  t.cache().invalidateAll();
  t.cache().resetStats();
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> xz(10.f, 1010.f), sl(-0.7f, 0.7f);
  std::vector<RaySample> rays(4096);
  for (RaySample& r : rays) r = {Vec3f(xz(rng), 110.f, xz(rng)), Vec3f(sl(rng), -1.f, sl(rng)).normalized(), 300.f};
  size_t i = 0, hits = 0;
  TerrainRayStats stats;
  for (auto _ : state) {
    const RaySample& r = rays[i++ & 4095];
    TerrainRayHit h;
    hits += raycastTerrain(t, r.origin.cast<double>(), r.dir.cast<double>(), r.length, h, &stats);
  }
  state.counters["hit_fraction"] = double(hits) / double(state.iterations());
  state.counters["cache_hit_rate"] = t.cache().stats().hitRate();
  state.counters["cache_MB"] = double(t.cache().bytes()) / 1e6;
  state.counters["chunks_traced_per_ray"] = double(stats.chunksTraced) / double(state.iterations());
  state.counters["chunks_stepped_per_ray"] = double(stats.chunksStepped) / double(state.iterations());
}

BENCHMARK(BM_BitmaskBroadphase_Memory_Hills1024)->Iterations(1);
BENCHMARK(BM_BitmaskBroadphase_Memory_World4096)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BitmaskBroadphase_AabbTest)->ArgName("large")->Arg(0)->Arg(1);
BENCHMARK(BM_BitmaskBroadphase_RebuildChunk);
BENCHMARK(BM_Mesher_Chunk);
BENCHMARK_CAPTURE(BM_ChunkMeshes_Build, KdTree, kKdTree)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ChunkMeshes_Build, btBvhQuantized, kBtQuantized)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ChunkMeshes_Build, btBvhNonQuantized, kBtNonQuantized)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ChunkMeshes_Raycast, KdTree, kKdTree);
BENCHMARK_CAPTURE(BM_ChunkMeshes_Raycast, btBvhQuantized, kBtQuantized);
BENCHMARK_CAPTURE(BM_ChunkMeshes_Raycast, btBvhNonQuantized, kBtNonQuantized);
BENCHMARK_CAPTURE(BM_Heightfield1M_Build, KdTree, kKdTree)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Heightfield1M_Build, KdTreeNoHeightBounds, kKdTreeNoHeightBounds)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Heightfield1M_Build, btBvhQuantized, kBtQuantized)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Heightfield1M_Build, btBvhNonQuantized, kBtNonQuantized)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Heightfield1M_Raycast, KdTree, kKdTree);
BENCHMARK_CAPTURE(BM_Heightfield1M_Raycast, KdTreeNoHeightBounds, kKdTreeNoHeightBounds);
BENCHMARK_CAPTURE(BM_Heightfield1M_Raycast, btBvhQuantized, kBtQuantized);
BENCHMARK_CAPTURE(BM_Heightfield1M_Raycast, btBvhNonQuantized, kBtNonQuantized);
BENCHMARK_CAPTURE(BM_Heightfield1M_Raycast, btHeightfield, kBtHeightfield);
BENCHMARK_CAPTURE(BM_Heightfield1M_AabbQuery2m, KdTree, kKdTree);
BENCHMARK_CAPTURE(BM_Heightfield1M_AabbQuery2m, btBvhQuantized, kBtQuantized);
BENCHMARK_CAPTURE(BM_Heightfield1M_AabbQuery2m, btBvhNonQuantized, kBtNonQuantized);
BENCHMARK(BM_TerrainRaycast)->ArgName("cacheMB")->Arg(64)->Arg(1);

}  // namespace
}  // namespace bw

BENCHMARK_MAIN();
