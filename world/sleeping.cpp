#include "world/sleeping.h"

#include <atomic>

#include "world/world_tuning.h"

namespace bw {

using namespace tuning;

void SleepState::reset(uint32_t bodies) {
  stillTime_.assign(bodies, 0.f);
  asleep_.assign(bodies, 0);
  carrierOfBody_.assign(bodies, kNoCarrier);
  rootCarrier_.assign(bodies, kNoCarrier);
  carried_.clear();
}

void SleepState::wakeTouched(std::span<const SolverContact> contacts, const BodyStore& bodies, bool noteCarriers) {
  for (const SolverContact& s : contacts) {
    for (uint32_t x : {s.a, s.b})
      if (asleep_[x]) wake(x);
    if (!noteCarriers) continue;
    // A dynamic body on a moving kinematic one (one at rest carries as the world does).
    for (const auto& [d, k] : {std::pair{s.a, s.b}, std::pair{s.b, s.a}}) {
      if (bodies.motion[d] != MotionType::Dynamic || bodies.motion[k] != MotionType::Kinematic) continue;
      if (!bodies.translates(k) && !bodies.turns(k)) continue;
      uint32_t& c = carrierOfBody_[d];
      if (c == kNoCarrier) {
        carried_.push_back(d);
        c = bodies.turns(k) ? kUnalikeCarriers : k;
      } else if (c != kUnalikeCarriers && !bodies.movesAlike(c, k)) {  // (false when k turns)
        c = kUnalikeCarriers;
      }
    }
  }
}

void SleepState::update(BodyStore& bodies, const Islands& islands, float dt, JobSystem& jobs, Profiler& profiler, int stage) {
  const uint32_t n = bodies.size();
  blocked_.assign(n, 0);
  // Each island's carrier, merged from its members' (serial, in contact order: only the bodies
  // touching a moving kinematic body, none in a world without one). Two unalike make it
  // unalike; the velocity it gives does not depend on which alike carrier came first.
  const bool carriers = !carried_.empty();
  for (uint32_t d : carried_) {
    const uint32_t c = carrierOfBody_[d];
    uint32_t& rc = rootCarrier_[islands.root(d)];
    if (rc == kNoCarrier) rc = c;
    else if (rc != kUnalikeCarriers && (c == kUnalikeCarriers || !bodies.movesAlike(rc, c))) rc = kUnalikeCarriers;
  }
  const auto carrierOf = [&](uint32_t body) { return carriers ? rootCarrier_[islands.root(body)] : kNoCarrier; };
  // Still times grow or restart, and an island with a member not yet ready may not sleep. Each
  // body writes its own still time; a blocked flag is only ever set to 1, so the threads that
  // set the same root's flag agree and the result is the same for any thread count.
  jobs.parallelFor(0, n, bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "sleep: still times", stage);
    for (uint32_t i = begin; i < end; ++i) {
      if (bodies.motion[i] != MotionType::Dynamic || asleep_[i]) continue;
      const uint32_t c = carrierOf(i);
      const Vec3f carried = c < kUnalikeCarriers ? bodies.linearVelocity[c] : Vec3f::Zero();
      const bool still = c != kUnalikeCarriers && (bodies.linearVelocity[i] - carried).norm() < kSleepLinear &&
                         bodies.angularVelocity[i].norm() < kSleepAngular;
      stillTime_[i] = still ? stillTime_[i] + dt : 0.f;
      if (stillTime_[i] < kSleepTime) std::atomic_ref<uint8_t>(blocked_[islands.root(i)]).store(1, std::memory_order_relaxed);
    }
  });
  // Every member of an island nobody blocked falls asleep (the join above orders the flags),
  // moving on with its carrier's velocity (a valid carrier does not turn).
  jobs.parallelFor(0, n, bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "sleep: islands fall asleep", stage + 1);
    for (uint32_t i = begin; i < end; ++i) {
      if (bodies.motion[i] != MotionType::Dynamic || asleep_[i] || blocked_[islands.root(i)]) continue;
      const uint32_t c = carrierOf(i);
      asleep_[i] = 1;
      bodies.linearVelocity[i] = c < kUnalikeCarriers ? bodies.linearVelocity[c] : Vec3f::Zero();
      bodies.angularVelocity[i] = Vec3f::Zero();
    }
  });
  // The notes cleared for the next substep (only the entries written).
  for (uint32_t d : carried_) {
    rootCarrier_[islands.root(d)] = kNoCarrier;
    carrierOfBody_[d] = kNoCarrier;
  }
  carried_.clear();
}

uint32_t SleepState::count() const {
  uint32_t n = 0;
  for (uint8_t a : asleep_) n += a;
  return n;
}

}  // namespace bw
