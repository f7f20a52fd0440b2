#include "world/sleeping.h"

#include "world/world_tuning.h"

namespace bw {

using namespace tuning;

void SleepState::reset(uint32_t bodies) {
  stillTime_.assign(bodies, 0.f);
  asleep_.assign(bodies, 0);
}

void SleepState::wakeTouched(const std::vector<SolverContact>& contacts) {
  for (const SolverContact& s : contacts)
    for (uint32_t x : {s.a, s.b})
      if (asleep_[x]) wake(x);
}

void SleepState::update(BodyStore& bodies, const Islands& islands, float dt) {
  const uint32_t n = bodies.size();
  for (uint32_t i = 0; i < n; ++i) {
    if (bodies.motion[i] != MotionType::Dynamic || asleep_[i]) continue;
    const bool still = bodies.linearVelocity[i].norm() < kSleepLinear && bodies.angularVelocity[i].norm() < kSleepAngular;
    stillTime_[i] = still ? stillTime_[i] + dt : 0.f;
  }
  // An island may sleep only if every member is ready.
  blocked_.assign(n, 0);
  for (uint32_t i = 0; i < n; ++i)
    if (bodies.motion[i] == MotionType::Dynamic && !asleep_[i] && stillTime_[i] < kSleepTime) blocked_[islands.root(i)] = 1;
  for (uint32_t i = 0; i < n; ++i) {
    if (bodies.motion[i] != MotionType::Dynamic || asleep_[i] || blocked_[islands.root(i)]) continue;
    asleep_[i] = 1;
    bodies.linearVelocity[i] = Vec3f::Zero();
    bodies.angularVelocity[i] = Vec3f::Zero();
  }
}

uint32_t SleepState::count() const {
  uint32_t n = 0;
  for (uint8_t a : asleep_) n += a;
  return n;
}

}  // namespace bw
