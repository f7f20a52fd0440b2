#pragma once
/// The baseline brickworld is measured against: the same scene in Bullet 3.24's
/// btDiscreteDynamicsWorld, each grid a btCompoundShape of its bricks (one child box per brick:
/// the article's "compounds" approach). Bodies start exactly where the World puts them (the
/// baseline mirrors a built World's initial state), with the same gravity, time step, substeps
/// and solver iterations, so the two runs do the same job.
#include <cstdint>
#include <memory>

#include "world/world.h"

namespace bw {

class BulletBaseline {
 public:
  /// Mirrors `world`'s bodies (call before stepping the World).
  explicit BulletBaseline(const World& world);
  ~BulletBaseline();
  /// One frame (the scene's time step, in its substeps).
  void step();
  /// Contact points in the dispatcher's manifolds after the last step.
  uint32_t contactCount() const;
  /// Seconds Bullet spent building the compound shapes.
  double buildSeconds() const { return buildSeconds_; }
  /// Lowest dynamic body and how many dynamic bodies move slower than 5 cm/s.
  void restingReport(uint32_t& resting, uint32_t& moving, double& lowestZ) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double buildSeconds_ = 0;
};

}  // namespace bw
