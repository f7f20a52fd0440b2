// Pairs with a terrain: solid contacts against the chunk triangles, then buoyancy and water
// drag from the water voxels the body displaces. In eight stages:
//   select (parallel, per pair): the terrain pairs, each one query or, for a small grid
//          (kBrickwiseGridBricks), one query per brick, counted per chunk of pairs;
//   select offsets (one thread): each chunk's offsets; a grid's hull is made here, lazily;
//   select queries (parallel, per pair): the queries written at their chunk's offsets;
//   plan   (parallel, per query): the shape, its pose and margin, the candidate triangles from
//          chunks already in the terrain's cache (TerrainContactPlan only reads), the water,
//          how many pieces the candidates make, whether the body was queried already;
//   cut    (one thread): the queries' first pieces (a sum over a compact count per query);
//   pieces (parallel, per piece): the contacts of a few candidate triangles each, so a body
//          lying across many triangles is spread over several jobs;
//   finish (parallel, per pair): each query's pieces' contacts joined in order, interior
//          edges and repeated points dropped; buoyancy when no body has two terrain queries,
//          and then counters, per job, for the pairs whose queries were all cached;
//   apply  (one thread, pair order): the jobs' counters summed; a pair with a query that
//          needed a chunk not yet meshed runs again in query order, that query the filling way
//          (the meshes stay lazy: only chunks a body touches are ever built, and in steady
//          state every chunk is cached); counters and buoyancy for what finish left.
// The contacts are the same whichever stage computes them (the pieces join in the serial
// query's order), so the state is the same for any thread count and any cache budget.
// note: the parallel reads do not refresh the cache's LRU order; a scene whose touched chunks
// exceed the cache budget re-meshes more than with serial queries (the default budget holds
// every shipped scene's chunks).
#include <algorithm>
#include <atomic>

#include "collision/bricks/brick_narrowphase.h"
#include "collision/terrain/terrain_contacts.h"
#include "world/world.h"
#include "world/world_tuning.h"

namespace bw {

using namespace tuning;

namespace {

uint32_t trianglesPerPiece(const QueryShape& s) {
  const bool convex = s.kind == QueryShape::Kind::Box || s.kind == QueryShape::Kind::Hull;
  return convex ? kConvexTrianglesPerPiece : kRoundTrianglesPerPiece;
}

}  // namespace

void World::terrainPairs(float dt) {
  if (terrains_.empty()) return;
  TerrainPairWork& w = terrainWork_;
  const uint32_t n = uint32_t(pairs_.size());
  const Vec3f g = scene_.settings.gravity.cast<float>();
  stats_.floating = 0;  // bodies in water in the last substep
  // select: each pair's queries counted in parallel (a pair a few nanoseconds: monument's 658
  // pairs were one serial job of 7 us a substep), offsets taken per chunk, grid hulls made on
  // one thread (the cache is not thread-safe; rare), then the queries written in parallel, each
  // chunk at its offset: pair order, as one thread would.
  const uint32_t selectGrain = grainFor(n, kMinPairGrain);
  const uint32_t chunks = JobSystem::chunkCount(0, n, selectGrain);
  w.pairQueries.resize(n);
  w.selectChunks.assign(chunks + 1, TerrainPairWork::SelectChunk{});
  jobs_.parallelFor(0, n, selectGrain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "terrain: select", stage_ + kTerrainStage);
    TerrainPairWork::SelectChunk counts;
    for (uint32_t k = begin; k < end; ++k) {
      w.pairQueries[k] = TerrainPairWork::kNoQuery;
      const uint32_t a = pairs_[k].a, b = pairs_[k].b;
      const bool terrainA = bodies_.shape[a].isTerrain();
      if (!terrainA && !bodies_.shape[b].isTerrain()) continue;
      if (!canCollide(a, b) || !pairMoves(a, b)) continue;
      const uint32_t body = terrainA ? b : a;
      pairFlipped_[k] = body == b;  // normals point from the terrain towards the body
      uint32_t count = 1;
      if (bodies_.shape[body].isGrid()) {
        // A small grid meets terrain brick by brick, each brick the box of its shape (as
        // against other grids: collideGrids), so a concave piece is not filled in by its hull;
        // a larger one through its convex approximation (as it meets other grids).
        const BrickGrid& grid = *grids_[bodies_.shape[body].grid];
        if (grid.brickCount() <= kBrickwiseGridBricks) {
          count = grid.brickCount();
          ++counts.brickwise;
        } else {
          ++counts.hulls;
        }
      }
      w.pairQueries[k] = count;
      counts.queries += count;
      ++counts.groups;
    }
    w.selectChunks[begin / selectGrain + 1] = counts;  // (offsets: summed below)
  });
  {
    ProfileZone z(profiler_, "terrain: select offsets", stage_ + kTerrainStage + 1);
    w.bodiesUnique = true;  // (a small grid's bricks are queries of one body)
    for (uint32_t c = 0; c < chunks; ++c) {
      TerrainPairWork::SelectChunk& next = w.selectChunks[c + 1];
      w.bodiesUnique &= next.brickwise == 0;
      const bool hulls = next.hulls != 0;
      next.queries += w.selectChunks[c].queries;
      next.groups += w.selectChunks[c].groups;
      if (!hulls) continue;
      // Made here, on one thread, the first time it is needed.
      for (uint32_t k = c * selectGrain; k < std::min(n, (c + 1) * selectGrain); ++k) {
        if (w.pairQueries[k] != 1) continue;
        const uint32_t body = pairFlipped_[k] ? pairs_[k].b : pairs_[k].a;
        if (!bodies_.shape[body].isGrid()) continue;
        BrickGrid& grid = *grids_[bodies_.shape[body].grid];
        if (grid.brickCount() > kBrickwiseGridBricks) grid.convexApproximation(scene_.settings.approximationDepth);
      }
    }
    w.queries.resize(w.selectChunks[chunks].queries);
    w.groups.resize(w.selectChunks[chunks].groups);
  }
  jobs_.parallelFor(0, n, selectGrain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "terrain: select queries", stage_ + kTerrainStage + 2);
    uint32_t at = w.selectChunks[begin / selectGrain].queries, group = w.selectChunks[begin / selectGrain].groups;
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t count = w.pairQueries[k];
      if (count == TerrainPairWork::kNoQuery) continue;
      TerrainPairWork::Query q;
      q.pair = k;
      q.body = pairFlipped_[k] ? pairs_[k].b : pairs_[k].a;
      q.terrain = bodies_.shape[pairFlipped_[k] ? pairs_[k].a : pairs_[k].b].terrain;
      w.groups[group++] = {k, at, count};
      const BodyShape& shape = bodies_.shape[q.body];
      if (shape.isGrid() && grids_[shape.grid]->brickCount() <= kBrickwiseGridBricks) {
        grids_[shape.grid]->forEachBrick([&](uint32_t id) {
          q.brick = id;
          w.queries[at++] = q;
        });
        continue;
      }
      w.queries[at++] = q;
    }
  });
  const uint32_t m = uint32_t(w.queries.size());
  if (w.plans.size() < m) w.plans.resize(m);
  w.pieceStart.resize(m + 1);
  w.queryRepeats.resize(m);
  w.bodyQueried.resize(bodies_.size(), 0);
  jobs_.parallelFor(0, m, grainFor(m, kMinTerrainGrain), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "terrain: plan", stage_ + kTerrainStage + 3);
    for (uint32_t i = begin; i < end; ++i) {
      TerrainPairWork::Query& q = w.queries[i];
      const BodyPair& p = pairs_[q.pair];
      q.pose = bodies_.shapePose(q.body);
      q.shape = bodies_.shape[q.body].primitive;
      if (q.brick != TerrainPairWork::kWholeBody) {
        const Brick& br = grids_[bodies_.shape[q.body].grid]->brick(q.brick);
        q.pose = RigidTransform{q.pose.pointToWorld(br.position), q.pose.rotation * br.rotation.quaternion()};
        q.shape = QueryShape::box(br.halfSize);
      } else if (bodies_.shape[q.body].isGrid()) {
        const ConvexApproximation& hull = grids_[bodies_.shape[q.body].grid]->convexApproximation(scene_.settings.approximationDepth);
        q.pose.translation = q.pose.pointToWorld(hull.shapeCenter());
        q.shape = hull.shape();
      }
      q.margin = tuning::kSpeculativeMargin + closingSpeed(q.body, q.body == p.a ? p.b : p.a) * dt;
      const Terrain& terrain = *terrains_[q.terrain];
      q.cached = w.plans[i].plan(terrain, q.shape, q.pose, q.margin);
      q.wet = bodies_.motion[q.body] == MotionType::Dynamic && terrainWaterContactChecked(terrain, q.shape, q.pose, q.water);
      const uint32_t per = trianglesPerPiece(q.shape);
      w.pieceStart[i + 1] = q.cached ? (w.plans[i].triangleCount() + per - 1) / per : 0;  // (a count: summed in cut)
      // A body with two whole-body queries (two terrains): its flag was set by the other, in
      // this job or another (a small grid's bricks are queries of one body, seen in select).
      // The flags go back to 0 in finish.
      w.queryRepeats[i] = q.brick == TerrainPairWork::kWholeBody &&
                          std::atomic_ref<uint8_t>(w.bodyQueried[q.body]).exchange(1, std::memory_order_relaxed) != 0;
    }
  });
  {
    // note: one pass over two compact arrays: the loop that cut the pieces here and checked the
    // bodies read every query's record (1.7 us a frame on monument, one thread).
    ProfileZone z(profiler_, "terrain: cut", stage_ + kTerrainStage + 4);
    w.pieceStart[0] = 0;
    for (uint32_t i = 0; i < m; ++i) {
      w.pieceStart[i + 1] += w.pieceStart[i];
      w.bodiesUnique &= w.queryRepeats[i] == 0;  // then buoyancy runs per query in parallel (finish)
    }
  }
  // Query i's pieces are [pieceStart[i], pieceStart[i + 1]), piece j of them its candidate
  // triangles [j * per, (j + 1) * per) (the last one shorter).
  const uint32_t pieceCount = w.pieceStart[m];
  if (w.pieceOutputs.size() < pieceCount) w.pieceOutputs.resize(pieceCount);
  jobs_.parallelFor(0, pieceCount, grainFor(pieceCount, kMinTerrainGrain), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "terrain pairs", stage_ + kTerrainStage + 5);
    // The query holding piece `begin`: the last whose first piece is at or before it.
    uint32_t query = uint32_t(std::upper_bound(w.pieceStart.begin(), w.pieceStart.begin() + m + 1, begin) - w.pieceStart.begin()) - 1;
    for (uint32_t i = begin; i < end; ++i) {
      while (i >= w.pieceStart[query + 1]) ++query;
      const uint32_t per = trianglesPerPiece(w.queries[query].shape), count = w.plans[query].triangleCount();
      const uint32_t first = (i - w.pieceStart[query]) * per;
      TerrainPairWork::PieceOutput& o = w.pieceOutputs[i];
      o.contacts.clear();
      o.faceNormals.clear();
      w.plans[query].contactsOfTriangles(first, std::min(count, first + per), o.contacts, o.faceNormals);
    }
  });
  const auto buoyancy = [&](const TerrainPairWork::Query& q) {
    // Archimedes: the displaced water's weight, applied at the centre of buoyancy, as an
    // impulse this substep; then drag in proportion to how deep the body sits.
    const uint32_t body = q.body;
    const float impulse = float(waterDensity_[q.terrain] * q.water.submergedVolume) * dt;
    const Vec3f j = -g * impulse;
    bodies_.linearVelocity[body] += j * bodies_.inverseMass[body];
    // note: only a body cut by the surface gets the righting torque (kBuoyancyTorqueBelowFraction).
    if (q.water.submergedFraction < kBuoyancyTorqueBelowFraction) {
      const Vec3f r = (q.water.centreOfBuoyancy - bodies_.position[body]).cast<float>();
      bodies_.angularVelocity[body] += bodies_.inverseInertiaWorld(body) * r.cross(j);
    }
    const float f = q.water.submergedFraction;
    bodies_.linearVelocity[body] *= std::max(0.f, 1.f - kWaterLinearDrag * f * dt);
    bodies_.angularVelocity[body] *= std::max(0.f, 1.f - kWaterAngularDrag * f * dt);
  };
  // A query's contacts: its pieces joined in order, interior edges and repeats dropped, appended
  // to its pair's list (a small grid's bricks one after another); a query planned from chunks
  // not in the cache runs whole the filling way (apply stage). Either way the same contacts.
  // A small grid's brick query: its contacts' features mix in the brick (warm starting tells
  // the bricks apart).
  const auto markBrick = [](const TerrainPairWork::Query& q, std::vector<Contact>& out, size_t start) {
    if (q.brick == TerrainPairWork::kWholeBody) return;
    for (size_t c = start; c < out.size(); ++c) out[c].featureB = smallFeature(out[c].featureB, q.brick);
  };
  const auto join = [&](uint32_t i, std::vector<Contact>& out, std::vector<Vec3f>& faceNormals) {
    const TerrainPairWork::Query& q = w.queries[i];
    const size_t start = out.size();
    faceNormals.clear();
    for (uint32_t p = w.pieceStart[i]; p < w.pieceStart[i + 1]; ++p) {
      const TerrainPairWork::PieceOutput& o = w.pieceOutputs[p];
      out.insert(out.end(), o.contacts.begin(), o.contacts.end());
      faceNormals.insert(faceNormals.end(), o.faceNormals.begin(), o.faceNormals.end());
    }
    finishTerrainContacts(out, start, faceNormals);
    markBrick(q, out, start);
  };
  const auto allCached = [&](const TerrainPairWork::Group& group) {
    for (uint32_t i = group.firstQuery; i < group.firstQuery + group.queryCount; ++i)
      if (!w.queries[i].cached) return false;
    return true;
  };
  // A finish job counts its groups' contacts and bodies in water when every query of a group
  // was planned from cached chunks and buoyancy ran here: then apply only sums the jobs' counts
  // and visits the jobs that hold a group to query again (monument: apply was a serial 1 us a
  // substep over every group, a tenth of its span at 16 threads outside the raft island).
  const uint32_t groupCount = uint32_t(w.groups.size());
  const uint32_t finishGrain = grainFor(groupCount, kMinTerrainGrain);
  w.finishChunks.assign(JobSystem::chunkCount(0, groupCount, finishGrain), TerrainPairWork::FinishChunk{});
  jobs_.parallelFor(0, groupCount, finishGrain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "terrain: finish", stage_ + kTerrainStage + 6);
    // note: thread_local scratch: the face normals of one query, joined from its pieces.
    thread_local std::vector<Vec3f> faceNormals;
    TerrainPairWork::FinishChunk counts;
    for (uint32_t g = begin; g < end; ++g) {
      const TerrainPairWork::Group& group = w.groups[g];
      std::vector<Contact>& out = pairContacts_[group.pair];
      out.clear();
      bool wet = false;
      for (uint32_t i = group.firstQuery; i < group.firstQuery + group.queryCount; ++i) {
        const TerrainPairWork::Query& q = w.queries[i];
        join(i, out, faceNormals);
        wet |= q.wet;
        if (w.bodiesUnique && q.wet) buoyancy(q);
        // plan's flag back to 0 (a body's two queries may be in two jobs: both write 0)
        if (q.brick == TerrainPairWork::kWholeBody) std::atomic_ref<uint8_t>(w.bodyQueried[q.body]).store(0, std::memory_order_relaxed);
      }
      if (group.queryCount > 1) reduceManifold(out, 0, scene_.settings.manifoldSize);  // a small grid's bricks: one manifold
      if (!w.bodiesUnique || !allCached(group)) {
        counts.applyLeft = true;
        continue;
      }
      counts.contacts += uint32_t(out.size());
      counts.floating += wet ? 1u : 0u;
    }
    w.finishChunks[begin / finishGrain] = counts;
  });
  ProfileZone z(profiler_, "terrain: apply", stage_ + kTerrainStage + 7);
  std::vector<Vec3f>& faceNormals = w.faceNormals;
  // A group its finish job did not count: queried again in query order when a query needed a
  // chunk not yet meshed (the uncached ones filling the cache), then counted; buoyancy here
  // when a body has two queries.
  const auto applyGroup = [&](const TerrainPairWork::Group& group) {
    const bool cached = allCached(group);
    if (w.bodiesUnique && cached) return;  // counted by its finish job
    std::vector<Contact>& out = pairContacts_[group.pair];
    if (!cached) {
      out.clear();
      for (uint32_t i = group.firstQuery; i < group.firstQuery + group.queryCount; ++i) {
        const TerrainPairWork::Query& q = w.queries[i];
        if (q.cached) {
          join(i, out, faceNormals);
          continue;
        }
        const size_t start = out.size();
        terrainContacts(*terrains_[q.terrain], q.shape, q.pose, q.margin, out);
        markBrick(q, out, start);
      }
      if (group.queryCount > 1) reduceManifold(out, 0, scene_.settings.manifoldSize);
    }
    stats_.terrainContacts += uint32_t(out.size());
    bool wet = false;
    for (uint32_t i = group.firstQuery; i < group.firstQuery + group.queryCount; ++i) {
      const TerrainPairWork::Query& q = w.queries[i];
      if (!q.wet) continue;
      if (!w.bodiesUnique) buoyancy(q);  // (a small grid's bricks each float by their own volume)
      wet = true;
    }
    stats_.floating += wet ? 1u : 0u;
  };
  for (uint32_t chunk = 0; chunk < uint32_t(w.finishChunks.size()); ++chunk) {
    const TerrainPairWork::FinishChunk& counts = w.finishChunks[chunk];
    stats_.terrainContacts += counts.contacts;
    stats_.floating += counts.floating;
    if (!counts.applyLeft) continue;
    for (uint32_t g = chunk * finishGrain; g < std::min(groupCount, (chunk + 1) * finishGrain); ++g)
      applyGroup(w.groups[g]);
  }
}

}  // namespace bw
