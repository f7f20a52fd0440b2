// Pairs with a terrain: solid contacts against the chunk triangles, then buoyancy and water
// drag from the water voxels the body displaces. In three stages:
//   shapes (one thread, pair order): each pair's shape and pose (a grid's hull is made lazily);
//   query  (parallel, per pair): contacts from chunks already in the terrain's cache
//          (terrainContactsCached only reads) and the water estimate, each into its own slot;
//   apply  (one thread, pair order): a pair that needed a chunk not yet meshed is queried the
//          filling way (the meshes stay lazy: only chunks a body touches are ever built, and
//          in steady state every chunk is cached); buoyancy and drag change the body's velocity
//          in pair order, as before.
// The contacts are the same whichever stage computes them, so the state is the same for any
// thread count and any cache budget.
// note: the parallel reads do not refresh the cache's LRU order; a scene whose touched chunks
// exceed the cache budget re-meshes more than with serial queries (the default budget holds
// every shipped scene's chunks).
#include <algorithm>

#include "collision/terrain/terrain_contacts.h"
#include "world/world.h"
#include "world/world_tuning.h"

namespace bw {

using namespace tuning;

void World::terrainPairs(float dt) {
  if (terrains_.empty()) return;
  const uint32_t n = uint32_t(pairs_.size());
  const Vec3f g = scene_.settings.gravity.cast<float>();
  stats_.floating = 0;  // bodies in water in the last substep
  terrainQueries_.clear();
  {
    ProfileZone z(profiler_, "terrain: shapes", stage_ + kTerrainStage);
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t a = pairs_[k].a, b = pairs_[k].b;
      const bool terrainA = bodies_.shape[a].isTerrain();
      if (!terrainA && !bodies_.shape[b].isTerrain()) continue;
      if (!canCollide(a, b) || (!active(a) && !active(b))) continue;
      TerrainQuery q;
      q.pair = k;
      q.body = terrainA ? b : a;
      q.terrain = bodies_.shape[terrainA ? a : b].terrain;
      q.pose = bodies_.shapePose(q.body);
      q.shape = bodies_.shape[q.body].primitive;
      if (bodies_.shape[q.body].isGrid()) {
        // A grid meets terrain through its convex approximation (as it meets other grids).
        const ConvexApproximation& hull = grids_[bodies_.shape[q.body].grid]->convexApproximation(scene_.settings.approximationDepth);
        q.pose.translation = q.pose.pointToWorld(hull.shapeCenter());
        q.shape = hull.shape();
      }
      q.margin = tuning::kSpeculativeMargin + closingSpeed(q.body, terrainA ? a : b) * dt;
      pairFlipped_[k] = q.body == b;  // normals point from the terrain towards the body
      terrainQueries_.push_back(q);
    }
  }
  const uint32_t m = uint32_t(terrainQueries_.size());
  jobs_.parallelFor(0, m, grainFor(m, kMinTerrainGrain), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "terrain pairs", stage_ + kTerrainStage + 1);
    for (uint32_t i = begin; i < end; ++i) {
      TerrainQuery& q = terrainQueries_[i];
      const Terrain& terrain = *terrains_[q.terrain];
      std::vector<Contact>& out = pairContacts_[q.pair];
      out.clear();
      q.cached = terrainContactsCached(terrain, q.shape, q.pose, q.margin, out);
      q.wet = bodies_.motion[q.body] == MotionType::Dynamic && terrainWaterContact(terrain, q.shape, q.pose, q.water);
    }
  });
  ProfileZone z(profiler_, "terrain: apply", stage_ + kTerrainStage + 2);
  for (const TerrainQuery& q : terrainQueries_) {
    std::vector<Contact>& out = pairContacts_[q.pair];
    if (!q.cached) terrainContacts(*terrains_[q.terrain], q.shape, q.pose, q.margin, out);
    stats_.terrainContacts += uint32_t(out.size());
    if (!q.wet) continue;
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
    ++stats_.floating;
  }
}

}  // namespace bw
