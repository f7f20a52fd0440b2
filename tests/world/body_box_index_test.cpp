// BodyBoxIndex (world/body_box_index.h) against brute force: seeded boxes from 0.2 to 500 long,
// clustered and far from the origin, with repeated min x values; queries anywhere, points
// and queries that end exactly where a box starts included. Every overlapping body must be visited, and any() must answer as brute force does.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "collision/core/seeded_random.h"
#include "world/body_box_index.h"

namespace bw {
namespace {

TEST(BodyBoxIndex, VisitsWhatBruteForceFindsAndAnswersAnyAlike) {
  SeededRandom r(41);
  // Rounds 6 and 7: every box starting at one x (one bucket), and one box 1e6 beyond the rest
  // (the others crowd into the first bucket).
  for (int round = 0; round < 8; ++round) {
    const Vec3d origin = round % 2 ? Vec3d(3e6, -2e6, 5e5) : Vec3d::Zero();
    const uint32_t n = round == 0 ? 0 : (round == 1 ? 1 : 200 * uint32_t(round % 6 + 1));
    std::vector<WorldAabb> boxes;
    std::vector<uint32_t> bodies;
    for (uint32_t i = 0; i < n; ++i) {
      const Vec3d c = origin + Vec3d(r.uniform(-300, 300), r.uniform(-30, 30), r.uniform(-5, 5)) * (i % 3 ? 1.0 : 0.1);
      Vec3d h(r.logUniform(0.1, 250), r.logUniform(0.1, 2), r.logUniform(0.1, 2));
      if (i % 7 == 0) h.x() = 0.1;  // thin along x
      WorldAabb b{c - h, c + h};
      if (i % 11 == 0 && !boxes.empty()) b.min.x() = boxes.back().min.x();  // equal min x
      if (round == 6) {
        b.min.x() = origin.x() - 1;
        b.max.x() = std::max(b.max.x(), b.min.x());
      }
      if (round == 7 && i == n / 2) b = {c + Vec3d(1e6, 0, 0), c + Vec3d(1e6 + 1, 1, 1)};
      boxes.push_back(b);
      bodies.push_back(r.below(n / 2 + 1));  // bodies own several boxes
    }
    BodyBoxIndex index;
    index.build(boxes, bodies);
    for (int q = 0; q < 400; ++q) {
      const Vec3d c = origin + Vec3d(r.uniform(-350, 350), r.uniform(-35, 35), r.uniform(-6, 6));
      const Vec3d h = q % 4 == 0 ? Vec3d::Zero() : Vec3d(r.logUniform(0.1, 100), r.logUniform(0.1, 5), r.logUniform(0.1, 5));
      WorldAabb query{c - h, c + h};
      if (q % 5 == 1 && n) {  // ends exactly where a box starts along x (closed intervals touch)
        const WorldAabb& b = boxes[r.below(n)];
        query = {Vec3d(b.min.x() - 2 * h.x(), b.min.y(), b.min.z()), Vec3d(b.min.x(), b.max.y(), b.max.z())};
      }
      std::vector<uint32_t> expected, visited;
      for (uint32_t i = 0; i < n; ++i)
        if (boxes[i].overlaps(query)) expected.push_back(bodies[i]);
      EXPECT_FALSE(index.any(query, [&](uint32_t body) {
        visited.push_back(body);
        return false;
      }));
      std::sort(expected.begin(), expected.end());
      std::sort(visited.begin(), visited.end());
      ASSERT_EQ(visited, expected) << "round " << round << ", query " << q;
      const uint32_t wanted = n ? bodies[r.below(n)] : 0;
      const bool found = std::find(expected.begin(), expected.end(), wanted) != expected.end();
      EXPECT_EQ(index.any(query, [&](uint32_t body) { return body == wanted; }), found);
    }
  }
}

}  // namespace
}  // namespace bw
