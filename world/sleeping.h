#pragma once
/// Sleeping: bodies that stay nearly still accumulate still time; an island sleeps when all of
/// its bodies have been still for kSleepTime (a resting pile sleeps together and wakes
/// together). Still means still relative to the island's carrier: the kinematic body in uniform
/// flight (no turn) its contacts rest on, or the world when it rests on no moving kinematic
/// body. A sleeping body keeps its carrier's velocity and rides it (the crates in a flying
/// ship's hold), skipped by gravity, the solver and contacts with every body that moves alike
/// (World::pairMoves); a contact with an awake body or one that moves otherwise (the carrier
/// turned or changed speed), or an edit of a grid it rests on, wakes it.
#include <cstdint>
#include <span>
#include <vector>

#include "jobs/job_system.h"
#include "jobs/profiler.h"
#include "world/body_store.h"
#include "world/islands.h"
#include "world/solver_contact.h"

namespace bw {

class SleepState {
 public:
  /// Every body awake, with no still time.
  void reset(uint32_t bodies);
  /// More bodies (split off a grid): the new ones awake, the others as they were.
  void grow(uint32_t bodies) {
    stillTime_.resize(bodies, 0.f);
    asleep_.resize(bodies, 0);
    carrierOfBody_.resize(bodies, kNoCarrier);
    rootCarrier_.resize(bodies, kNoCarrier);
  }
  bool asleep(uint32_t body) const { return asleep_[body] != 0; }
  /// Wakes the body (and restarts its still time).
  void wake(uint32_t body) {
    asleep_[body] = 0;
    stillTime_[body] = 0.f;
  }
  /// Wakes every sleeping body a contact touches (an awake body touched it, or one that moves
  /// otherwise). With `noteCarriers` (sleeping on) also notes, for each dynamic body, the moving
  /// kinematic bodies it touches, for update(): one in uniform flight is its carrier, several
  /// unalike or a turning one let it not sleep.
  void wakeTouched(std::span<const SolverContact> contacts, const BodyStore& bodies, bool noteCarriers);
  /// After a substep of dt seconds: still times grow or restart, and every island (as last
  /// built) whose dynamic bodies have all been still for kSleepTime relative to its carrier
  /// falls asleep, its velocities set to the carrier's (zero without one). Parallel over
  /// bodies on jobs (zones at stage and stage + 1); the same result for any thread count.
  void update(BodyStore& bodies, const Islands& islands, float dt, JobSystem& jobs, Profiler& profiler, int stage);
  /// Dynamic bodies asleep.
  uint32_t count() const;

 private:
  static constexpr uint32_t kNoCarrier = ~0u, kUnalikeCarriers = ~0u - 1;
  std::vector<float> stillTime_;  // seconds each body has been nearly still
  std::vector<uint8_t> asleep_;
  std::vector<uint8_t> blocked_;  // update() scratch: per island root, a member is not ready
  // wakeTouched() to update(): per dynamic body, the moving kinematic body it touches (or
  // kUnalikeCarriers), valid for the bodies in carried_ (in contact order), kNoCarrier else;
  // per island root, its carrier merged from its members' (kNoCarrier for every root between
  // two updates).
  std::vector<uint32_t> carrierOfBody_, rootCarrier_;
  std::vector<uint32_t> carried_;
};

}  // namespace bw
