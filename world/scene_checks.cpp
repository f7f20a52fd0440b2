#include "world/scene_checks.h"

#include "collision/core/obb.h"
#include "world/world.h"

namespace bw {

SceneCheckTracker::SceneCheckTracker(const World& world) : world_(world) {
  const SceneChecks& checks = world.scene().checks;
  for (const std::vector<std::string>& chain : checks.linked)
    for (size_t k = 0; k + 1 < chain.size(); ++k)
      pairs_.push_back({world.gridBody(chain[k]), world.gridBody(chain[k + 1]), chain[k] + " / " + chain[k + 1]});
  for (const SceneChecks::EndsIn& e : checks.endsIn) ends_.push_back({world.gridBody(e.grid), e.grid, e.min, e.max});
  parted_.assign(pairs_.size(), 0);
  links_.pairs = uint32_t(pairs_.size());
  update();
}

bool SceneCheckTracker::linked(const Pair& p) const {
  const BodyStore& bodies = world_.bodies();
  const RigidTransform poseA = bodies.shapePose(p.a), poseB = bodies.shapePose(p.b);
  const Aabb boundsA = world_.grid(bodies.shape[p.a].grid).bounds(), boundsB = world_.grid(bodies.shape[p.b].grid).bounds();
  // b's bounds as an oriented box in a's grid frame (centre through double, per the precision rule).
  return overlaps(poseA.obbToLocal(poseB.pointToWorld(boundsB.center()), poseB.rotation, boundsB.halfExtent()), boundsA);
}

void SceneCheckTracker::update() {
  links_.partedNow = 0;
  for (size_t k = 0; k < pairs_.size(); ++k) {
    if (linked(pairs_[k])) continue;
    ++links_.partedNow;
    if (parted_[k]) continue;
    parted_[k] = 1;
    ++links_.everParted;
    if (links_.firstParted.empty()) {
      links_.firstParted = pairs_[k].names;
      links_.firstPartedFrame = world_.frame();
    }
  }
}

std::vector<EndsInReport> SceneCheckTracker::endsIn() const {
  std::vector<EndsInReport> out;
  for (const End& e : ends_) {
    const Vec3d p = world_.bodies().position[e.body];
    out.push_back({e.grid, (p.array() >= e.min.array()).all() && (p.array() <= e.max.array()).all(), p});
  }
  return out;
}

bool SceneCheckTracker::pass() const {
  if (links_.everParted) return false;
  for (const EndsInReport& e : endsIn())
    if (!e.inside) return false;
  return true;
}

}  // namespace bw
