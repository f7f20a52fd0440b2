// The world's broadphase (pairs kept over fat boxes, found anew for moved proxies) and its
// dynamic tree, against brute force: adversarial boxes (0.2 m to 500 m, thin plates, clusters,
// 10^7 m from the origin), bodies that creep, jump, leave and come back, static proxies that
// change, owners of several static proxies, and bad input refused with nothing changed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "collision/core/errors.h"
#include "collision/core/seeded_random.h"
#include "world/dynamic_bounds_tree.h"
#include "world/incremental_broadphase.h"

namespace bw {
namespace {

// A box of 0.2 m to 500 m (some thin plates) near `centre`.
WorldAabb randomBox(SeededRandom& r, const Vec3d& centre, double spread) {
  const Vec3d c = centre + Vec3d(r.normal(), r.normal(), r.normal()) * spread;
  Vec3d h = Vec3d::Constant(r.logUniform(0.1, 250));
  if (r.unit() < 0.1) h[int(r.uniform(0, 3)) % 3] = 0.001;
  return {c - h, c + h};
}

std::vector<uint32_t> bruteQuery(const std::vector<WorldAabb>& boxes, const std::vector<uint32_t>& live, const WorldAabb& q) {
  std::vector<uint32_t> out;
  for (uint32_t id : live)
    if (boxes[id].overlaps(q)) out.push_back(id);
  return out;
}

TEST(DynamicBoundsTree, EditsKeepItValidAndQueriesMatchBruteForce) {
  for (const double offset : {0.0, 1e7}) {
    SeededRandom r(offset == 0 ? 41 : 42);
    const Vec3d origin = Vec3d::Constant(offset);
    const uint32_t n = 1500;
    std::vector<WorldAabb> boxes(n);
    for (uint32_t i = 0; i < n; ++i) boxes[i] = randomBox(r, origin + (i % 3 == 0 ? Vec3d::Zero() : Vec3d(400, 0, 0)), i % 3 == 0 ? 5 : 300);
    DynamicBoundsTree tree;
    std::vector<uint32_t> leaf(n, DynamicBoundsTree::kNull), live;
    // Inserted one by one, half of them; the other half later in bulk with the first.
    for (uint32_t i = 0; i < n; i += 2) {
      leaf[i] = tree.insert(boxes[i], i);
      live.push_back(i);
    }
    tree.validate();
    EXPECT_LE(tree.height(), 40);
    const auto check = [&](int round) {
      tree.validate();
      ASSERT_EQ(tree.leafCount(), live.size());
      for (int q = 0; q < 60; ++q) {
        const WorldAabb box = randomBox(r, origin, 300);
        std::vector<uint32_t> found;
        tree.query(box, [&](uint32_t id) { found.push_back(id); });
        std::sort(found.begin(), found.end());
        std::vector<uint32_t> sortedLive = live;
        std::sort(sortedLive.begin(), sortedLive.end());
        ASSERT_EQ(found, bruteQuery(boxes, sortedLive, box)) << "round " << round << ", offset " << offset;
      }
    };
    check(0);
    for (int round = 1; round <= 6; ++round) {
      // Moves (small and far), removals and inserts, in a seeded order.
      for (int k = 0; k < 400; ++k) {
        const uint32_t i = uint32_t(r.uniform(0, n)) % n;
        if (leaf[i] == DynamicBoundsTree::kNull) {
          leaf[i] = tree.insert(boxes[i], i);
          live.push_back(i);
        } else if (r.unit() < 0.3) {
          tree.remove(leaf[i]);
          leaf[i] = DynamicBoundsTree::kNull;
          live.erase(std::find(live.begin(), live.end(), i));
        } else {
          const Vec3d d = r.unit() < 0.5 ? Vec3d(r.normal(), r.normal(), r.normal()) * 0.3 : Vec3d(r.normal(), r.normal(), r.normal()) * 200;
          boxes[i].min += d;
          boxes[i].max += d;
          tree.move(leaf[i], boxes[i]);
        }
      }
      check(round);
      if (round == 3) {
        // Rebuilt in bulk over every box: leaves handed back, then edited on.
        std::vector<uint32_t> ids(n);
        for (uint32_t i = 0; i < n; ++i) ids[i] = i;
        std::vector<uint32_t> leaves;
        tree.build(boxes, ids, leaves);
        live = ids;
        leaf = leaves;
        for (uint32_t i = 0; i < n; ++i) ASSERT_EQ(tree.id(leaf[i]), i);
        EXPECT_LE(tree.height(), 33);  // cell splits: log2(1500) = 10.6, clusters deeper
        check(round);
      }
    }
  }
}

TEST(DynamicBoundsTree, RefitsLoosenWithoutLosingAnythingAndSelfPairsMatchBruteForce) {
  for (const double offset : {0.0, 1e7}) {
    SeededRandom r(offset == 0 ? 44 : 45);
    const Vec3d origin = Vec3d::Constant(offset);
    const uint32_t n = 1200;
    std::vector<WorldAabb> boxes(n);
    std::vector<uint32_t> ids(n), leaves;
    for (uint32_t i = 0; i < n; ++i) {
      boxes[i] = randomBox(r, origin, i % 4 == 0 ? 3 : 150);  // a dense cluster among sparse boxes
      ids[i] = i;
    }
    DynamicBoundsTree tree;
    tree.build(boxes, ids, leaves);
    uint32_t refitted = 0, moved = 0;
    for (int round = 0; round < 5; ++round) {
      for (uint32_t i = 0; i < n; i += 3) {
        // Small steps stay in place (ancestors grow), long ones are taken out and put back.
        const double step = i % 2 == 0 ? 0.05 : 40;
        const Vec3d d = Vec3d(r.normal(), r.normal(), r.normal()) * step;
        boxes[i].min += d;
        boxes[i].max += d;
        const uint32_t before = tree.leafCount();
        const uint32_t grown = tree.refit(leaves[i], boxes[i], 2);
        ASSERT_LE(grown, 2u);
        ASSERT_EQ(tree.leafCount(), before);
        ASSERT_EQ(tree.id(leaves[i]), i);  // the leaf index stays either way
        (step < 1 ? refitted : moved) += 1;
      }
      tree.validate();  // every box holds its children's
      std::vector<uint8_t> wanted(n, 0);
      for (uint32_t i = 0; i < n; i += 7) wanted[i] = 1;
      for (const bool filtered : {false, true}) {
        std::vector<BodyPair> got, expected;
        JobSystem jobs(2);
        tree.selfPairs(got, filtered ? wanted.data() : nullptr, round % 2 ? &jobs : nullptr);
        for (uint32_t i = 0; i < n; ++i)
          for (uint32_t j = i + 1; j < n; ++j)
            if (boxes[i].overlaps(boxes[j]) && (!filtered || wanted[i] || wanted[j])) expected.push_back({i, j});
        ASSERT_EQ(got, expected) << "round " << round << (filtered ? ", filtered" : "") << ", offset " << offset;
        if (!filtered) {
          EXPECT_GT(got.size(), 1000u);
        }
      }
      for (int q = 0; q < 40; ++q) {
        const WorldAabb box = randomBox(r, origin, 150);
        std::vector<uint32_t> found;
        tree.query(box, [&](uint32_t id) { found.push_back(id); });
        std::sort(found.begin(), found.end());
        ASSERT_EQ(found, bruteQuery(boxes, ids, box));
      }
    }
    EXPECT_GT(refitted, 0u);
    EXPECT_GT(moved, 0u);
  }
}

TEST(DynamicBoundsTree, BulkBuildsOfAnySizeAndBadCallsAreRefused) {
  SeededRandom r(43);
  for (const uint32_t n : {0u, 1u, 2u, 3u, 7u, 2049u, 5000u}) {
    std::vector<WorldAabb> boxes;
    std::vector<uint32_t> ids;
    for (uint32_t i = 0; i < n; ++i) {
      // Many identical boxes (equal centres: the split's tie rule) among random ones.
      boxes.push_back(i % 4 == 0 ? WorldAabb{Vec3d::Zero(), Vec3d::Constant(1)} : randomBox(r, Vec3d::Zero(), 50));
      ids.push_back(7 * i + 3);
    }
    DynamicBoundsTree tree;
    std::vector<uint32_t> leaves;
    JobSystem jobs(2);
    tree.build(boxes, ids, leaves, &jobs);
    tree.validate();
    ASSERT_EQ(tree.leafCount(), n);
    std::vector<uint32_t> all;
    tree.leafIds(all);
    std::sort(all.begin(), all.end());
    EXPECT_EQ(all, ids);
    const WorldAabb q{Vec3d::Constant(-10), Vec3d::Constant(10)};
    std::vector<uint32_t> found, expected;
    tree.query(q, [&](uint32_t id) { found.push_back(id); });
    for (uint32_t i = 0; i < n; ++i)
      if (boxes[i].overlaps(q)) expected.push_back(ids[i]);
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, expected) << n;
  }
  DynamicBoundsTree tree;
  std::vector<uint32_t> leaves;
  EXPECT_THROW(tree.build({WorldAabb{Vec3d::Zero(), Vec3d::Zero()}}, {}, leaves), InvalidInput);
  const uint32_t a = tree.insert({Vec3d::Zero(), Vec3d::Ones()}, 1);
  const uint32_t b = tree.insert({Vec3d::Ones(), Vec3d::Constant(2)}, 2);
  EXPECT_THROW(tree.remove(tree.leafCount() + 5), InvalidInput);  // past the nodes
  EXPECT_THROW(tree.move(9999, {Vec3d::Zero(), Vec3d::Ones()}), InvalidInput);
  EXPECT_THROW(tree.refit(9999, {Vec3d::Zero(), Vec3d::Ones()}, 2), InvalidInput);
  tree.remove(a);
  EXPECT_THROW(tree.remove(a), InvalidInput);  // freed
  tree.validate();
  EXPECT_EQ(tree.leafCount(), 1u);
  EXPECT_EQ(tree.id(b), 2u);
}

// Every pair of overlapping proxies not both static, as pairs of owners, each once.
std::vector<BodyPair> brutePairs(const std::vector<WorldAabb>& b, const std::vector<uint8_t>& st, const std::vector<uint32_t>* owner) {
  std::vector<BodyPair> out;
  for (uint32_t i = 0; i < b.size(); ++i)
    for (uint32_t j = i + 1; j < b.size(); ++j) {
      const uint32_t oi = owner ? (*owner)[i] : i, oj = owner ? (*owner)[j] : j;
      if (!(st[i] && st[j]) && oi != oj && b[i].overlaps(b[j])) out.push_back({std::min(oi, oj), std::max(oi, oj)});
    }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// A world of proxies for the broadphase: bodies (one moving proxy each, or static), static grids
// as strings of cover boxes, proxies listed in owner order as the world lists them.
struct ProxyWorld {
  struct Body {
    WorldAabb box;
    Vec3d velocity;
    bool isStatic = false;
    bool present = true;  // a grid edited away has no proxy
    std::vector<WorldAabb> covers;  // a static grid's boxes (then `box` is unused)
  };
  std::vector<Body> bodies;
  std::vector<WorldAabb> bounds;
  std::vector<uint8_t> isStatic;
  std::vector<uint32_t> owner;
  void list() {
    bounds.clear();
    isStatic.clear();
    owner.clear();
    for (uint32_t i = 0; i < bodies.size(); ++i) {
      const Body& b = bodies[i];
      if (!b.present) continue;
      if (!b.covers.empty()) {
        for (const WorldAabb& c : b.covers) {
          bounds.push_back(c);
          isStatic.push_back(1);
          owner.push_back(i);
        }
        continue;
      }
      bounds.push_back(b.box);
      isStatic.push_back(b.isStatic);
      owner.push_back(i);
    }
  }
};

ProxyWorld makeWorld(SeededRandom& r, uint32_t n, const Vec3d& origin) {
  ProxyWorld w;
  for (uint32_t i = 0; i < n; ++i) {
    ProxyWorld::Body b;
    if (i % 150 == 0) {  // a static grid: a street of 30 cover boxes
      const Vec3d base = origin + Vec3d(r.uniform(-60, 60), r.uniform(-60, 60), 0);
      for (int k = 0; k < 30; ++k) {
        const Vec3d c = base + Vec3d(4.0 * k, 0, 0);
        b.covers.push_back({c - Vec3d(2.5, 3, 1), c + Vec3d(2.5, 3, 1)});
      }
      b.isStatic = true;
    } else {
      const bool pile = i % 3 == 0;  // a dense pile: long lists of neighbours
      const Vec3d c = origin + (pile ? Vec3d(r.uniform(0, 8), r.uniform(0, 8), r.uniform(0, 8))
                                     : Vec3d(r.uniform(-100, 100), r.uniform(-100, 100), r.uniform(0, 30)));
      Vec3d h = Vec3d::Constant(i % 97 == 0 ? r.logUniform(20, 250) : r.logUniform(0.1, 2));
      if (i % 23 == 0) h.z() = 0.001;  // a thin plate
      b.box = {c - h, c + h};
      b.isStatic = i % 11 == 0;
      b.velocity = b.isStatic ? Vec3d(Vec3d::Zero()) : Vec3d(Vec3d(r.normal(), r.normal(), -r.unit() * 3) * (i % 5 == 0 ? 0.0 : 0.1));  // some rest
    }
    w.bodies.push_back(b);
  }
  w.list();
  return w;
}

// One frame of change: most bodies creep, some jump, some leave or come back, sometimes a
// static grid is edited or a body comes to rest as static (or starts moving again).
void changeWorld(ProxyWorld& w, SeededRandom& r, int frame) {
  for (uint32_t i = 0; i < w.bodies.size(); ++i) {
    ProxyWorld::Body& b = w.bodies[i];
    if (!b.covers.empty()) continue;
    if (!b.isStatic) {
      const Vec3d d = r.unit() < 0.02 ? Vec3d(r.normal(), r.normal(), r.normal()) * 80 : b.velocity;  // a jump
      b.box.min += d;
      b.box.max += d;
    }
    if (r.unit() < 0.01) b.present = !b.present;  // leaves, or comes back
  }
  if (frame % 4 == 1) w.bodies[0].covers[3].max.z() += 0.5;  // a static grid edited: a cover box grew
  if (frame % 5 == 2) {
    const uint32_t i = 1 + uint32_t(r.uniform(0, double(w.bodies.size() - 1))) % uint32_t(w.bodies.size() - 1);
    if (w.bodies[i].covers.empty()) w.bodies[i].isStatic = !w.bodies[i].isStatic;
  }
  w.list();
}

TEST(IncrementalBroadphase, MatchesBruteForceAndTheSweepWhileBodiesMoveJumpLeaveAndReturn) {
  for (const double offset : {0.0, 1e7}) {
    SeededRandom r(offset == 0 ? 51 : 52);
    ProxyWorld w = makeWorld(r, 1200, Vec3d::Constant(offset));
    IncrementalBroadphase bp;
    SweepAndPrune sap;
    std::vector<BodyPair> pairs, swept;
    uint64_t moved = 0;
    for (int frame = 0; frame < 24; ++frame) {
      bp.update(w.bounds, w.isStatic, pairs, nullptr, nullptr, -1, &w.owner);
      ASSERT_EQ(pairs, brutePairs(w.bounds, w.isStatic, &w.owner)) << "frame " << frame << ", offset " << offset;
      sap.update(w.bounds, w.isStatic, swept, nullptr, nullptr, -1, &w.owner);
      ASSERT_EQ(pairs, swept);
      bp.movingTree().validate();
      if (frame > 0) moved += bp.lastMoved();
      changeWorld(w, r, frame);
    }
    EXPECT_GT(pairs.size(), 300u);
    EXPECT_GT(moved, 1000u);                // proxies left their fat boxes
    EXPECT_GT(bp.staticBuilds(), 5u);       // and static changes were taken
    EXPECT_GT(bp.fatPairs(), pairs.size());  // the kept pairs hold more than the overlapping ones
    // A fresh instance (nothing kept) gives the same pairs: the output depends only on bounds.
    IncrementalBroadphase fresh;
    std::vector<BodyPair> again;
    fresh.update(w.bounds, w.isStatic, again, nullptr, nullptr, -1, &w.owner);
    EXPECT_EQ(again, brutePairs(w.bounds, w.isStatic, &w.owner));
  }
}

TEST(IncrementalBroadphase, ManyMovesRebuildTheTreeInBulkAndFewMoveLeaves) {
  // Without owners (proxy i is body i): a frame where every body jumps is built in bulk; a
  // frame where a few creep past their boxes moves leaves; pairs equal brute force in both.
  SeededRandom r(53);
  const uint32_t n = 3000;
  std::vector<WorldAabb> b(n);
  std::vector<uint8_t> st(n, 0);
  auto place = [&](uint32_t i) { b[i] = randomBox(r, Vec3d::Zero(), 200); };
  for (uint32_t i = 0; i < n; ++i) {
    place(i);
    st[i] = i % 9 == 0;
  }
  IncrementalBroadphase bp;
  std::vector<BodyPair> pairs;
  bp.update(b, st, pairs);
  EXPECT_EQ(bp.movingBuilds(), 1u);  // the first frame: every proxy new
  // Frames in threes: every body jumps (built in bulk); they stop, and their boxes, stretched
  // for the jump, are made again (in bulk); a few creep past their boxes (leaves moved).
  for (int frame = 0; frame < 9; ++frame) {
    const int phase = frame % 3;
    for (uint32_t i = 0; i < n; ++i)
      if (!st[i] && (phase == 0 || (phase == 2 && i % 100 == 1))) {
        const Vec3d d = phase == 0 ? Vec3d(r.normal(), r.normal(), r.normal()) * 30 : Vec3d(5, 0, 0);  // past any fat box
        b[i].min += d;
        b[i].max += d;
      }
    const uint64_t builds = bp.movingBuilds();
    bp.update(b, st, pairs);
    ASSERT_EQ(pairs, brutePairs(b, st, nullptr)) << "frame " << frame;
    EXPECT_EQ(bp.movingBuilds(), builds + (phase < 2 ? 1 : 0)) << "frame " << frame;
    if (phase < 2) {
      EXPECT_GT(bp.lastMoved(), n / 2) << "frame " << frame;
    } else {
      EXPECT_GT(bp.lastMoved(), 20u) << "frame " << frame;
      EXPECT_LT(bp.lastMoved(), 40u) << "frame " << frame;  // only the creepers: the rest fit their boxes
    }
    bp.movingTree().validate();
  }
}

TEST(IncrementalBroadphase, OwnersWithStaticAndMovingProxiesPairOnce) {
  // An owner may hold static proxies beside its one moving proxy (a body with fixed parts): a
  // body touching both pairs with it once. Owners listed out of order are taken too.
  SeededRandom r(55);
  std::vector<WorldAabb> b;
  std::vector<uint8_t> st;
  std::vector<uint32_t> owner;
  for (uint32_t body = 0; body < 400; ++body) {
    const uint32_t o = (body * 37) % 400;  // owners out of order
    const Vec3d c(r.uniform(-30, 30), r.uniform(-30, 30), r.uniform(0, 10));
    const Vec3d h = Vec3d::Constant(r.logUniform(0.2, 3));
    b.push_back({c - h, c + h});
    st.push_back(0);
    owner.push_back(o);
    if (body % 10 == 0)
      for (int k = 1; k <= 3; ++k) {  // three fixed parts next to it
        b.push_back({c - h + Vec3d(k * 1.5, 0, 0), c + h + Vec3d(k * 1.5, 0, 0)});
        st.push_back(1);
        owner.push_back(o);
      }
  }
  IncrementalBroadphase bp;
  std::vector<BodyPair> pairs;
  for (int frame = 0; frame < 5; ++frame) {
    bp.update(b, st, pairs, nullptr, nullptr, -1, &owner);
    ASSERT_EQ(pairs, brutePairs(b, st, &owner)) << "frame " << frame;
    for (uint32_t i = 0; i < b.size(); ++i)
      if (!st[i]) {
        const Vec3d d(r.normal() * 0.4, r.normal() * 0.4, 0);
        b[i].min += d;
        b[i].max += d;
      }
  }
  EXPECT_GT(pairs.size(), 100u);
}

TEST(IncrementalBroadphase, BadInputIsRefusedAndChangesNothing) {
  SeededRandom r(54);
  ProxyWorld w = makeWorld(r, 300, Vec3d::Zero());
  IncrementalBroadphase bp;
  std::vector<BodyPair> pairs;
  bp.update(w.bounds, w.isStatic, pairs, nullptr, nullptr, -1, &w.owner);
  const std::vector<BodyPair> before = pairs;
  const auto expectError = [&](std::vector<WorldAabb> b, std::vector<uint8_t> st, std::vector<uint32_t> owner, const char* words) {
    std::vector<BodyPair> out{{1, 2}};
    try {
      bp.update(b, st, out, nullptr, nullptr, -1, &owner);
      FAIL() << "accepted: " << words;
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  uint32_t moving = 0;
  while (w.isStatic[moving]) ++moving;
  std::vector<WorldAabb> nan = w.bounds;
  nan[moving].max.y() = std::nan("");
  expectError(nan, w.isStatic, w.owner, ("body " + std::to_string(moving)).c_str());
  std::vector<WorldAabb> inverted = w.bounds;
  std::swap(inverted[moving].min, inverted[moving].max);
  inverted[moving].min.x() += 1;
  expectError(inverted, w.isStatic, w.owner, "inverted");
  expectError(w.bounds, std::vector<uint8_t>(w.bounds.size() - 1, 0), w.owner, "static flags");
  expectError(w.bounds, w.isStatic, std::vector<uint32_t>(w.bounds.size() + 1, 0), "owners");
  std::vector<uint32_t> twice = w.owner;
  uint32_t other = moving + 1;
  while (w.isStatic[other]) ++other;
  twice[other] = twice[moving];  // one owner, two moving proxies
  expectError(w.bounds, w.isStatic, twice, "two moving proxies");
  std::vector<uint32_t> huge = w.owner;
  huge[moving] = 1u << 30;
  expectError(w.bounds, w.isStatic, huge, "over the limit");
  // Nothing changed: the same input gives the same pairs, and after motion, brute force's.
  bp.update(w.bounds, w.isStatic, pairs, nullptr, nullptr, -1, &w.owner);
  EXPECT_EQ(pairs, before);
  changeWorld(w, r, 0);
  bp.update(w.bounds, w.isStatic, pairs, nullptr, nullptr, -1, &w.owner);
  EXPECT_EQ(pairs, brutePairs(w.bounds, w.isStatic, &w.owner));
  // Every proxy gone, then back: nothing kept from before.
  const std::vector<WorldAabb> none;
  const std::vector<uint8_t> noFlags;
  const std::vector<uint32_t> noOwners;
  bp.update(none, noFlags, pairs, nullptr, nullptr, -1, &noOwners);
  EXPECT_TRUE(pairs.empty());
  bp.update(w.bounds, w.isStatic, pairs, nullptr, nullptr, -1, &w.owner);
  EXPECT_EQ(pairs, brutePairs(w.bounds, w.isStatic, &w.owner));
  bp.movingTree().validate();
}

}  // namespace
}  // namespace bw
