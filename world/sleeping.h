#pragma once
/// Sleeping: bodies that stay nearly still accumulate still time; an island sleeps when all of
/// its bodies have been still for kSleepTime (a resting pile sleeps together and wakes
/// together). A sleeping body is skipped by gravity, contacts with other sleeping or static
/// bodies, the solver and integration; a contact with an awake body or an edit of a grid it
/// rests on wakes it.
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
  }
  bool asleep(uint32_t body) const { return asleep_[body] != 0; }
  /// Wakes the body (and restarts its still time).
  void wake(uint32_t body) {
    asleep_[body] = 0;
    stillTime_[body] = 0.f;
  }
  /// Wakes every sleeping body a contact touches (an awake body touched it).
  void wakeTouched(std::span<const SolverContact> contacts);
  /// After a substep of dt seconds: still times grow or restart, and every island (as last
  /// built) whose dynamic bodies have all been still for kSleepTime falls asleep, its
  /// velocities zeroed. Parallel over bodies on jobs (zones at stage and stage + 1); the same
  /// result for any thread count.
  void update(BodyStore& bodies, const Islands& islands, float dt, JobSystem& jobs, Profiler& profiler, int stage);
  /// Dynamic bodies asleep.
  uint32_t count() const;

 private:
  std::vector<float> stillTime_;  // seconds each body has been nearly still
  std::vector<uint8_t> asleep_;
  std::vector<uint8_t> blocked_;  // update() scratch: per island root, a member is not ready
};

}  // namespace bw
