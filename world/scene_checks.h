#pragma once
/// The scene's own checks (SceneDescription::checks) followed through a run: chains that must
/// stay linked and grids that must end inside a box. Like containment it reads poses only, so
/// it judges Bullet's run too (on the judge World that follows Bullet's poses).
///
/// Linked: two interlocked rings always share a point (where one's wire passes through the
/// other's hole), so their oriented bounds (each grid's brick bounds in its pose) overlap; a
/// ring that passed through another falls away from it. Checked after every frame: a pair that
/// parts even once fails the run, whether or not it meets again.
///
///   SceneCheckTracker checks(world);
///   for (...) { world.step(); checks.update(); }
///   checks.pass();
#include <cstdint>
#include <string>
#include <vector>

#include "collision/core/math_types.h"

namespace bw {

class World;

struct LinkCheckReport {
  uint32_t pairs = 0;             ///< neighbouring grids in all chains
  uint32_t partedNow = 0;         ///< pairs apart after the last update
  uint32_t everParted = 0;        ///< pairs apart after any update
  uint32_t firstPartedFrame = 0;  ///< World::frame() of the first update with a pair apart, 0 if none
  std::string firstParted;        ///< "a / b" of the first pair that parted, empty if none
};

struct EndsInReport {
  std::string grid;
  bool inside = false;
  Vec3d position = Vec3d::Zero();  ///< the grid body's centre of mass (origin when not dynamic) now
};

class SceneCheckTracker {
 public:
  /// The world's scene's checks, with its grid names resolved to bodies (SceneError for a name
  /// that is not one of the world's grids).
  explicit SceneCheckTracker(const World& world);
  /// Call after each step (or World::setPoses).
  void update();
  const LinkCheckReport& links() const { return links_; }
  std::vector<EndsInReport> endsIn() const;
  /// Whether the scene declares checks at all.
  bool any() const { return !pairs_.empty() || !ends_.empty(); }
  /// No pair ever parted and every ends_in grid is inside its box now.
  bool pass() const;

 private:
  struct Pair {
    uint32_t a, b;
    std::string names;
  };
  struct End {
    uint32_t body;
    std::string grid;
    Vec3d min, max;
  };
  bool linked(const Pair& p) const;
  const World& world_;
  std::vector<Pair> pairs_;
  std::vector<uint8_t> parted_;  // per pair: parted at some update
  std::vector<End> ends_;
  LinkCheckReport links_;
};

}  // namespace bw
