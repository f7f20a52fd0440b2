// The contact solver on hand-built bodies: warm starting matches impulses by pair and feature
// at full width (ids above 2^20 do not collide), and a resting box's impulse carries over; on
// seeded random manifolds it picks what a brute-force search of the last substep picks.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "world/contact_solver.h"
#include "world/world_tuning.h"

namespace bw {
namespace {

// A static ground (body 0) and two dynamic unit boxes (bodies 1 and 2) resting on it.
BodyStore groundAndTwoBoxes() {
  BodyStore bodies;
  bodies.add(Vec3d::Zero(), Quatf::Identity(), MotionType::Static, BodyShape{}, 0.f, Vec3f::Zero());
  for (double x : {0.0, 5.0}) {
    const uint32_t id = bodies.add(Vec3d(x, 0, 0.5), Quatf::Identity(), MotionType::Dynamic, BodyShape{}, 1.f, Vec3f::Constant(6.f));
    bodies.linearVelocity[id] = Vec3f(0, 0, -1);  // pressing into the ground
  }
  return bodies;
}

// The rest of a substep after prepare(), default settings: islands, the solve, the relax pass,
// the velocities stored and the impulses kept for the next substep's warm start.
void solvePrepared(ContactSolver& solver, BodyStore& bodies, JobSystem& jobs, Profiler& profiler) {
  const SceneSettings settings;
  Islands islands;
  islands.build(solver.contacts(), bodies.motion, jobs, profiler, 0);
  islands.groupContacts(jobs, profiler, 0);
  solver.loadBodies(bodies, jobs, profiler);
  solver.solve(islands, bodies.motion, false, settings, jobs, profiler, 0);
  solver.solve(islands, bodies.motion, true, settings, jobs, profiler, 0);
  solver.storeBodies(bodies, jobs, profiler);
  solver.keepImpulses(jobs, profiler, 0);
}

// One solve of the given pairs, each with one contact under its box, ending with the relax
// pass that stores the impulses for the next substep's warm start.
void solveOnce(ContactSolver& solver, BodyStore& bodies, const std::vector<BodyPair>& pairs,
               const std::vector<uint32_t>& features, JobSystem& jobs, Profiler& profiler) {
  SceneSettings settings;
  std::vector<std::vector<Contact>> contacts;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const Vec3d under = bodies.position[pairs[k].b] - Vec3d(0, 0, 0.5);
    contacts.push_back({Contact{under, Vec3f::UnitZ(), 0.001f, features[k], 0}});
  }
  const std::vector<uint8_t> flipped(pairs.size(), 1);  // normal from the ground (a) to the box (b)
  solver.prepare(bodies, pairs, contacts, flipped, settings, 1.f / 60, jobs, profiler, 0);
  solvePrepared(solver, bodies, jobs, profiler);
}

TEST(ContactSolver, WarmStartMatchesPairAndFeatureAtFullWidth) {
  JobSystem jobs(1);
  Profiler profiler;
  BodyStore bodies = groundAndTwoBoxes();
  ContactSolver solver;
  // Substep 1: pair (0, 1) with feature 0. Under a packed key (a << 40) ^ (b << 20) ^ feature
  // it reads 1 << 20, the same as pair (0, 2) with feature 3 << 20 (brick ids above 2^20).
  solveOnce(solver, bodies, {{0, 1}}, {0u}, jobs, profiler);
  ASSERT_EQ(solver.contacts().size(), 1u);
  ASSERT_GT(solver.contacts()[0].lambdaN, 0.f) << "the box pressing down must get a normal impulse";

  // Substep 2, same point: pair (0, 1) again warm-starts from its own impulse (the control),
  // while pair (0, 2) with the colliding feature must start cold.
  bodies.position[2] = bodies.position[1];
  SceneSettings settings;
  const std::vector<BodyPair> pairs = {{0, 1}, {0, 2}};
  std::vector<std::vector<Contact>> contacts = {{Contact{Vec3d(0, 0, 0), Vec3f::UnitZ(), 0.001f, 0u, 0}},
                                                {Contact{Vec3d(0, 0, 0), Vec3f::UnitZ(), 0.001f, 3u << 20, 0}}};
  solver.prepare(bodies, pairs, contacts, std::vector<uint8_t>(2, 1), settings, 1.f / 60, jobs, profiler, 0);
  ASSERT_EQ(solver.contacts().size(), 2u);
  EXPECT_GT(solver.contacts()[0].lambdaN, 0.f) << "same pair and feature: warm-started";
  EXPECT_EQ(solver.contacts()[1].lambdaN, 0.f) << "another pair whose packed key would collide: cold";
  EXPECT_EQ(solver.contacts()[1].lambdaT1, 0.f);
  EXPECT_EQ(solver.contacts()[1].lambdaT2, 0.f);
}

TEST(ContactSolver, WarmStartKeepsFeaturesAboveTwoToTheTwentyApart) {
  JobSystem jobs(1);
  Profiler profiler;
  BodyStore bodies = groundAndTwoBoxes();
  ContactSolver solver;
  // Brick ids 5 and 5 + 2^20 on the same pair are different bricks.
  solveOnce(solver, bodies, {{0, 1}}, {5u}, jobs, profiler);
  ASSERT_GT(solver.contacts()[0].lambdaN, 0.f);
  SceneSettings settings;
  const Vec3d under = bodies.position[1] - Vec3d(0, 0, 0.5);
  std::vector<std::vector<Contact>> contacts = {{Contact{under, Vec3f::UnitZ(), 0.001f, 5u + (1u << 20), 0}}};
  solver.prepare(bodies, {{0, 1}}, contacts, std::vector<uint8_t>(1, 1), settings, 1.f / 60, jobs, profiler, 0);
  EXPECT_EQ(solver.contacts()[0].lambdaN, 0.f);
}

// Seeded random manifolds: pairs among a row of boxes with 0-4 contacts each (features drawn
// from a few, so a pair repeats them), solved once; then new contacts near the old points. Each
// new contact must warm-start from what a brute-force scan of the last substep's contacts picks:
// same pair and feature, the nearest point within the radius, the earliest contact on a tie.
// Pairs in key order take keepImpulses' per-pair sorts, shuffled pairs its sort of the whole.
TEST(ContactSolver, WarmStartPicksWhatABruteForceScanPicks) {
  for (const bool shuffled : {false, true}) {
    for (const int threads : {1, 4}) {
      SCOPED_TRACE(testing::Message() << (shuffled ? "shuffled pairs" : "pairs in key order") << ", threads " << threads);
      std::mt19937 rng(911u + threads + (shuffled ? 100u : 0u));
      JobSystem jobs(threads);
      Profiler profiler;
      BodyStore bodies;
      bodies.add(Vec3d::Zero(), Quatf::Identity(), MotionType::Static, BodyShape{}, 0.f, Vec3f::Zero());
      for (int i = 0; i < 300; ++i) {
        const uint32_t id = bodies.add(Vec3d(3.0 * i, 0, 0.5), Quatf::Identity(), MotionType::Dynamic, BodyShape{}, 1.f,
                                       Vec3f::Constant(6.f));
        bodies.linearVelocity[id] = Vec3f(0.3f * (i % 3), 0, -0.01f * float(i + 1));  // every pair approaches
      }
      std::vector<BodyPair> pairs;
      // Sparse, as piles are: each box on the ground or on one of the two boxes before it
      // (a dense web of pairs leaves most impulses at zero, and zeros match anything).
      for (uint32_t a = 0; a < bodies.size(); ++a)
        for (uint32_t b = a + 1; b < bodies.size(); ++b)
          if ((a == 0 && rng() % 2 == 0) || (a > 0 && b - a <= 2 && rng() % 3 == 0)) pairs.push_back({a, b});
      if (shuffled) std::shuffle(pairs.begin(), pairs.end(), rng);
      // A pair's contacts: features from {0..3}, points on a coarse lattice under its b body
      // (so points repeat exactly: ties) plus a small jitter on some.
      const auto manifolds = [&] {
        std::vector<std::vector<Contact>> out(pairs.size());
        for (size_t k = 0; k < pairs.size(); ++k) {
          const uint32_t count = rng() % 5;
          for (uint32_t c = 0; c < count; ++c) {
            const Vec3d point = bodies.position[pairs[k].b] + Vec3d(0.02 * (rng() % 5), 0.02 * (rng() % 5), -0.5) +
                                (rng() % 2 ? Vec3d(1e-3 * (rng() % 7), 0, 0) : Vec3d::Zero());
            out[k].push_back(Contact{point, Vec3f::UnitZ(), 0.01f * (1 + rng() % 4), uint32_t(rng() % 4), 0});
          }
        }
        return out;
      };
      SceneSettings settings;
      const std::vector<uint8_t> flipped(pairs.size(), 1);
      ContactSolver solver;
      solver.prepare(bodies, pairs, manifolds(), flipped, settings, 1.f / 60, jobs, profiler, 0);
      solvePrepared(solver, bodies, jobs, profiler);
      const std::vector<SolverContact> last(solver.contacts().begin(), solver.contacts().end());
      const std::vector<SolverContactExtras> lastExtras(solver.contactExtras().begin(), solver.contactExtras().end());
      ASSERT_GT(last.size(), 300u);
      uint32_t picked = 0, warm = 0;
      solver.prepare(bodies, pairs, manifolds(), flipped, settings, 1.f / 60, jobs, profiler, 0);
      for (size_t i = 0; i < solver.contacts().size(); ++i) {
        const SolverContact& s = solver.contacts()[i];
        const SolverContactExtras& x = solver.contactExtras()[i];
        const SolverContact* pick = nullptr;
        double best = tuning::kWarmStartRadius * tuning::kWarmStartRadius;
        for (size_t j = 0; j < last.size(); ++j) {
          const SolverContactExtras& o = lastExtras[j];
          if (o.pairKey != x.pairKey || o.feature != x.feature) continue;
          const double d2 = (o.point - x.point).squaredNorm();
          if (d2 < best) best = d2, pick = &last[j];
        }
        ASSERT_EQ(s.lambdaN, pick ? pick->lambdaN : 0.f);
        ASSERT_EQ(s.lambdaT1, pick ? pick->lambdaT1 : 0.f);
        ASSERT_EQ(s.lambdaT2, pick ? pick->lambdaT2 : 0.f);
        picked += pick != nullptr;
        warm += pick && pick->lambdaN > 0.f;
      }
      EXPECT_GT(picked, 100u) << "too few contacts matched for the test to mean anything";
      EXPECT_GT(warm, 40u) << "too few matched contacts carry an impulse for the test to mean anything";
    }
  }
}

}  // namespace
}  // namespace bw
