#include "world/sleeping.h"

#include <atomic>

#include "world/world_tuning.h"

namespace bw {

using namespace tuning;

void SleepState::reset(uint32_t bodies) {
  stillTime_.assign(bodies, 0.f);
  asleep_.assign(bodies, 0);
}

void SleepState::wakeTouched(std::span<const SolverContact> contacts) {
  for (const SolverContact& s : contacts)
    for (uint32_t x : {s.a, s.b})
      if (asleep_[x]) wake(x);
}

void SleepState::update(BodyStore& bodies, const Islands& islands, float dt, JobSystem& jobs, Profiler& profiler, int stage) {
  const uint32_t n = bodies.size();
  blocked_.assign(n, 0);
  // Still times grow or restart, and an island with a member not yet ready may not sleep. Each
  // body writes its own still time; a blocked flag is only ever set to 1, so the threads that
  // set the same root's flag agree and the result is the same for any thread count.
  jobs.parallelFor(0, n, bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "sleep: still times", stage);
    for (uint32_t i = begin; i < end; ++i) {
      if (bodies.motion[i] != MotionType::Dynamic || asleep_[i]) continue;
      const bool still = bodies.linearVelocity[i].norm() < kSleepLinear && bodies.angularVelocity[i].norm() < kSleepAngular;
      stillTime_[i] = still ? stillTime_[i] + dt : 0.f;
      if (stillTime_[i] < kSleepTime) std::atomic_ref<uint8_t>(blocked_[islands.root(i)]).store(1, std::memory_order_relaxed);
    }
  });
  // Every member of an island nobody blocked falls asleep (the join above orders the flags).
  jobs.parallelFor(0, n, bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "sleep: islands fall asleep", stage + 1);
    for (uint32_t i = begin; i < end; ++i) {
      if (bodies.motion[i] != MotionType::Dynamic || asleep_[i] || blocked_[islands.root(i)]) continue;
      asleep_[i] = 1;
      bodies.linearVelocity[i] = Vec3f::Zero();
      bodies.angularVelocity[i] = Vec3f::Zero();
    }
  });
}

uint32_t SleepState::count() const {
  uint32_t n = 0;
  for (uint8_t a : asleep_) n += a;
  return n;
}

}  // namespace bw
