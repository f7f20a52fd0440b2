#pragma once
// A solver contact's fields drawn at random, for the solver's bit-for-bit tests (contact_update,
// island_lanes), in one order of draws on every compiler (collision/support/sequenced_draws.h).
#include <random>

#include "collision/support/sequenced_draws.h"
#include "world/solver_contact.h"

namespace bw::test {

/// Normal, tangents, biases, friction, arms, angular responses, masses and impulses of s, at the
/// scale `scale` (its bodies a and b are the caller's).
inline void drawSolverContact(std::mt19937& rng, float scale, SolverContact& s) {
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  const auto vec = [&](float k) { return drawVec3([&](int) { return u(rng) * k; }); };
  s.normal = vec(1.f).normalized();
  s.t1 = s.normal.unitOrthogonal();
  s.t2 = s.normal.cross(s.t1);
  s.bias = u(rng) * scale;
  s.relaxBias = u(rng) * scale * 0.1f;
  s.friction = unit(rng) * 1.2f;
  s.rA = vec(scale);
  s.rB = vec(scale);
  for (int d = 0; d < 3; ++d) {
    s.angA[d] = vec(unit(rng));
    s.angB[d] = vec(unit(rng));
  }
  s.massN = unit(rng) * 5.f;
  s.massT1 = unit(rng) * 5.f;
  s.massT2 = unit(rng) * 5.f;
  s.lambdaN = unit(rng) < 0.3f ? 0.f : unit(rng) * scale;
  s.lambdaT1 = u(rng) * s.friction * s.lambdaN;
  s.lambdaT2 = u(rng) * s.friction * s.lambdaN;
}

}  // namespace bw::test
