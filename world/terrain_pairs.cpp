// Pairs with a terrain: solid contacts against the chunk triangles, then buoyancy and water
// drag from the water voxels the body displaces. On one thread, in pair order: the terrain's
// chunk cache is filled by the queries.
#include <algorithm>

#include "collision/terrain/terrain_contacts.h"
#include "world/world.h"
#include "world/world_tuning.h"

namespace bw {

using namespace tuning;

// Pairs with a terrain, in pair order on this thread: solid contacts against the chunk
// triangles, and buoyancy plus drag from the water voxels the body displaces.
void World::terrainPairs(float dt) {
  if (terrains_.empty()) return;
  const uint32_t n = uint32_t(pairs_.size());
  const Vec3f g = scene_.settings.gravity.cast<float>();
  stats_.floating = 0;  // bodies in water in the last substep
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t a = pairs_[k].a, b = pairs_[k].b;
    const bool terrainA = bodies_.shape[a].isTerrain();
    if (!terrainA && !bodies_.shape[b].isTerrain()) continue;
    if (!canCollide(a, b) || (!active(a) && !active(b))) continue;
    const uint32_t body = terrainA ? b : a, terrainBody = terrainA ? a : b;
    Terrain& terrain = *terrains_[bodies_.shape[terrainBody].terrain];
    RigidTransform pose = bodies_.shapePose(body);
    QueryShape shape = bodies_.shape[body].primitive;
    if (bodies_.shape[body].isGrid()) {
      // A grid meets terrain through its convex approximation (as it meets other grids).
      const ConvexApproximation& hull = grids_[bodies_.shape[body].grid]->convexApproximation(scene_.settings.approximationDepth);
      pose.translation = pose.pointToWorld(hull.shapeCenter());
      shape = hull.shape();
    }
    std::vector<Contact>& out = pairContacts_[k];
    out.clear();
    const float margin = tuning::kSpeculativeMargin + closingSpeed(body, terrainBody) * dt;
    terrainContacts(terrain, shape, pose, margin, out);
    pairFlipped_[k] = body == b;  // normals point from the terrain towards the body
    stats_.terrainContacts += uint32_t(out.size());

    WaterContact water;
    if (bodies_.motion[body] != MotionType::Dynamic || !terrainWaterContact(terrain, shape, pose, water)) continue;
    // Archimedes: the displaced water's weight, applied at the centre of buoyancy, as an
    // impulse this substep; then drag in proportion to how deep the body sits.
    const float impulse = float(waterDensity_[bodies_.shape[terrainBody].terrain] * water.submergedVolume) * dt;
    const Vec3f j = -g * impulse;
    bodies_.linearVelocity[body] += j * bodies_.inverseMass[body];
    // note: only a body cut by the surface gets the righting torque (kBuoyancyTorqueBelowFraction).
    if (water.submergedFraction < kBuoyancyTorqueBelowFraction) {
      const Vec3f r = (water.centreOfBuoyancy - bodies_.position[body]).cast<float>();
      bodies_.angularVelocity[body] += bodies_.inverseInertiaWorld(body) * r.cross(j);
    }
    const float f = water.submergedFraction;
    bodies_.linearVelocity[body] *= std::max(0.f, 1.f - kWaterLinearDrag * f * dt);
    bodies_.angularVelocity[body] *= std::max(0.f, 1.f - kWaterAngularDrag * f * dt);
    ++stats_.floating;
  }
}

}  // namespace bw
