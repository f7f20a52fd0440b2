#include "world/contact_solver.h"

#include <algorithm>
#include <cmath>

#include "collision/core/assert.h"
#include "world/contact_update.h"
#include "world/world_tuning.h"

namespace bw {

using namespace tuning;

namespace {
// The radius a body rolls on: spheres and capsules roll, every other shape rests on faces.
float rollingRadius(const BodyShape& shape) {
  if (shape.isGrid() || shape.isTerrain()) return 0.f;
  const QueryShape::Kind k = shape.primitive.kind;
  return k == QueryShape::Kind::Sphere || k == QueryShape::Kind::Capsule ? shape.primitive.radius : 0.f;
}
}  // namespace

// One solver contact from contact c of a pair whose solver bodies are a and b (the normal points
// from b towards a).
void ContactSolver::makeContact(const BodyStore& bodies, const BodyPair& pair, uint32_t a, uint32_t b, const Contact& c,
                                CacheRange cached, const SceneSettings& settings, float dt, SolverContact& s,
                                SolverContactExtras& x) const {
  // note: written field by field in place (the records are reused between substeps): the
  // impulses start cold, shock and rolling off, until set below.
  s.lambdaN = s.lambdaT1 = s.lambdaT2 = 0.f;
  x.shockLower = 0;
  x.height = 0;
  x.lambdaR1 = x.lambdaR2 = 0.f;
  s.a = a;
  s.b = b;
  x.point = c.position;
  s.normal = c.normal;
  const float depth = c.depth;
  x.pairKey = (uint64_t(pair.a) << 32) | pair.b;
  x.feature = c.featureB;
  s.rA = (c.position - bodies.position[a]).cast<float>();
  s.rB = (c.position - bodies.position[b]).cast<float>();
  const Vec3f n = s.normal;
  s.t1 = (std::abs(n.x()) > kTangentThreshold ? Vec3f(n.y(), -n.x(), 0) : Vec3f(0, n.z(), -n.y())).normalized();
  s.t2 = n.cross(s.t1);
  const Mat3f& iA = inverseInertiaWorld_[a];
  const Mat3f& iB = inverseInertiaWorld_[b];
  const Vec3f dirs[3] = {n, s.t1, s.t2};
  float masses[3];
  for (int d = 0; d < 3; ++d) {
    s.angA[d] = iA * s.rA.cross(dirs[d]);
    s.angB[d] = iB * s.rB.cross(dirs[d]);
    const float m = bodies.inverseMass[a] + bodies.inverseMass[b] + s.angA[d].cross(s.rA).dot(dirs[d]) +
                    s.angB[d].cross(s.rB).dot(dirs[d]);
    masses[d] = m > 0 ? 1.f / m : 0.f;
  }
  s.massN = masses[0];
  s.massT1 = masses[1];
  s.massT2 = masses[2];
  if (settings.shockPropagation && bodies.motion[a] == MotionType::Dynamic && bodies.motion[b] == MotionType::Dynamic) {
    // The lower body (along gravity) is the support: in the shock sweep only the upper one moves.
    const Vec3d up = -settings.gravity.normalized();
    const double ha = up.dot(bodies.position[a]), hb = up.dot(bodies.position[b]);
    if (std::isfinite(ha) && std::abs(ha - hb) > kShockHeightEpsilon) {
      x.shockLower = ha < hb ? 1 : 2;
      x.height = std::min(ha, hb);
      for (int d = 0; d < 3; ++d) {
        const float m = x.shockLower == 1 ? bodies.inverseMass[b] + s.angB[d].cross(s.rB).dot(dirs[d])
                                          : bodies.inverseMass[a] + s.angA[d].cross(s.rA).dot(dirs[d]);
        x.shockMass[d] = m > 0 ? 1.f / m : 0.f;
      }
    }
  }
  s.friction = std::sqrt(bodies.friction[a] * bodies.friction[b]);
  s.rolling = settings.rollingResistance * std::max(rollingRadius(bodies.shape[a]), rollingRadius(bodies.shape[b]));
  if (s.rolling > 0.f)
    for (int d = 0; d < 2; ++d) {
      const Vec3f axis = d == 0 ? s.t1 : s.t2;
      x.rollA[d] = iA * axis;
      x.rollB[d] = iB * axis;
      const float m = axis.dot(x.rollA[d]) + axis.dot(x.rollB[d]);
      x.massR[d] = m > 0 ? 1.f / m : 0.f;
    }
  const Vec3f vRel = bodies.linearVelocity[a] + bodies.angularVelocity[a].cross(s.rA) - bodies.linearVelocity[b] -
                     bodies.angularVelocity[b].cross(s.rB);
  const float vn = vRel.dot(n);
  // Penetrating: push out (Baumgarte) and restitute fast impacts. Speculative (a gap of -depth):
  // the bodies may approach by at most the gap this step.
  const float bounce = vn < -kBounceThreshold ? -kRestitution * vn : 0.f;
  s.bias = depth >= 0.f ? std::min(kBaumgarte / dt * std::max(depth - kSlop, 0.f), kMaxPushOut) + bounce : depth / dt;
  // The relax pass after integration keeps restitution and speculative gaps but drops the
  // push-out, so no push-out velocity survives into the next step (resting stacks stay put).
  s.relaxBias = depth >= 0.f ? bounce : depth / dt;
  // Warm start from the nearest cached impulse of the same pair and feature (`cached` holds the
  // pair's impulses, in feature order).
  const CachedImpulse key{x.pairKey, x.feature, 0, {}, 0, 0, 0};
  auto range = std::equal_range(cached.first, cached.second, key);
  double best = kWarmStartRadius * kWarmStartRadius;
  for (auto it = range.first; it != range.second; ++it) {
    const double d2 = (it->point - x.point).squaredNorm();
    if (d2 < best) {
      best = d2;
      s.lambdaN = it->n;
      s.lambdaT1 = it->t1;
      s.lambdaT2 = it->t2;
    }
  }
}

void ContactSolver::prepare(const BodyStore& bodies, const std::vector<BodyPair>& pairs,
                            const std::vector<std::vector<Contact>>& pairContacts, const std::vector<uint8_t>& flipped,
                            const SceneSettings& settings, float dt, JobSystem& jobs, Profiler& profiler, int stage,
                            int offsetsStage) {
  if (offsetsStage < 0) offsetsStage = stage + 2;
  coloured_ = false;  // new contacts: the split islands are coloured again
  const uint32_t n = bodies.size();
  inverseInertiaWorld_.resize(n);
  jobs.parallelFor(0, n, tuning::bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "prepare: inertia", stage);
    for (uint32_t i = begin; i < end; ++i) inverseInertiaWorld_[i] = bodies.inverseInertiaWorld(i);
  });
  // Pair k's contacts go to [first_[k], first_[k + 1]): every pair fills its own range, in
  // parallel, in the order a serial loop would (the same list for any thread count).
  const uint32_t pairCount = uint32_t(pairs.size());
  first_.resize(pairCount + 1);
  first_[0] = 0;
  // The offsets: each chunk of pairs sums its own (first_ relative to the chunk), the chunks'
  // sums are added up here, then each chunk adds its start. One thread over every pair was
  // 48 us a frame on crate_pile (6,900 pairs), serial at any thread count.
  // note: whether the pairs with contacts come in strictly increasing key order (keepImpulses'
  // fast path) is read here off the compact pair list, per chunk and across the chunks' ends; a
  // scan of the contacts' keys after the relax pass missed once per pair (crate_pile on two
  // threads: 38 us a frame, serial).
  const uint32_t offsetGrain = tuning::grainFor(pairCount, tuning::kMinPairGrain);
  offsetChunks_.resize(JobSystem::chunkCount(0, pairCount, offsetGrain));
  jobs.parallelFor(0, pairCount, offsetGrain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "prepare: offsets", offsetsStage);
    OffsetChunk c;
    for (uint32_t k = begin; k < end; ++k) {
      c.contacts += uint32_t(pairContacts[k].size());
      first_[k + 1] = c.contacts;
      if (pairContacts[k].empty()) continue;
      const uint64_t key = (uint64_t(pairs[k].a) << 32) | pairs[k].b;  // makeContact's pairKey
      c.inOrder = c.inOrder && !(c.any && key <= c.lastKey);
      if (!c.any) c.firstKey = key;
      c.any = true;
      c.lastKey = key;
    }
    offsetChunks_[begin / offsetGrain] = c;
  });
  pairsInKeyOrder_ = true;
  bool anyKey = false;
  uint64_t lastKey = 0;
  uint32_t total = 0;
  for (OffsetChunk& c : offsetChunks_) {
    pairsInKeyOrder_ = pairsInKeyOrder_ && c.inOrder && !(anyKey && c.any && c.firstKey <= lastKey);
    if (c.any) lastKey = c.lastKey;
    anyKey = anyKey || c.any;
    const uint32_t start = total;
    total += c.contacts;
    c.contacts = start;  // now the chunk's start
  }
  // The contacts' jobs hold equal weight, a pair weighing 1 and each of its contacts 1 more
  // (pair k's weight starts at w(k) = first_[k] + k): pairs cut evenly left crates_on_grid's jobs
  // 1-12 us (the pairs near the end of the list had no contacts), the longest a third over the
  // stage's work / 16. Job j starts at the first pair whose weight starts at or past j / jobs of
  // the total: found by the chunk whose pairs' weights span that point, as it places its offsets.
  const uint64_t weight = uint64_t(total) + pairCount;
  const uint32_t jobCount = uint32_t(std::clamp<uint64_t>(weight / kMinPrepareWeight, 1, tuning::kTargetJobs));
  prepareJobStart_.resize(jobCount + 1);
  prepareJobStart_[0] = 0;
  prepareJobStart_[jobCount] = pairCount;
  const uint32_t offsetChunkCount = uint32_t(offsetChunks_.size());
  jobs.parallelFor(0, pairCount, offsetGrain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "prepare: offsets", offsetsStage + 1);
    const uint32_t c = begin / offsetGrain;
    const uint32_t start = offsetChunks_[c].contacts;
    for (uint32_t k = begin; k < end; ++k) first_[k + 1] += start;
    // This chunk's weights: [w(begin), w(end)), w(end) the next chunk's first (first_[begin] is
    // the chunk before's to write: its start stands in).
    const uint64_t lo = uint64_t(start) + begin;
    const uint64_t hi = uint64_t(c + 1 < offsetChunkCount ? offsetChunks_[c + 1].contacts : total) + end;
    uint32_t k = begin;
    for (uint32_t j = 1; j < jobCount; ++j) {
      const uint64_t at = weight * j / jobCount;
      if (at < lo || at >= hi) continue;
      while (k < end && uint64_t(k == begin ? start : first_[k]) + k < at) ++k;
      prepareJobStart_[j] = k;
    }
  });
#ifdef BW_ENABLE_ASSERTS
  for (uint32_t j = 0; j < jobCount; ++j) {  // each start against a binary search of the weights
    const uint64_t at = weight * j / jobCount;
    uint32_t lo = 0, hi = pairCount;
    while (lo < hi) {
      const uint32_t mid = lo + (hi - lo) / 2;
      if (uint64_t(first_[mid]) + mid < at) lo = mid + 1;
      else hi = mid;
    }
    BW_ASSERT(prepareJobStart_[j] == lo);
  }
#endif
  resizeForOverwrite(contacts_, total);  // every field a contact reads is written by makeContact
  resizeForOverwrite(extras_, total);
  jobs.parallelFor(0, jobCount, 1, [&](uint32_t jobBegin, uint32_t jobEnd) {
    ProfileZone z(profiler, "prepare: contacts", stage + 1);
    for (uint32_t k = prepareJobStart_[jobBegin]; k < prepareJobStart_[jobEnd]; ++k) {
      if (pairContacts[k].empty()) continue;
      // Solver convention: the normal points from b towards a.
      const uint32_t a = flipped[k] ? pairs[k].b : pairs[k].a;
      const uint32_t b = flipped[k] ? pairs[k].a : pairs[k].b;
      uint32_t slot = first_[k];
      // note: one search of the cache per pair, not per contact (it was a third of prepare).
      const CacheRange cached = std::equal_range(cache_.cbegin(), cache_.cend(), (uint64_t(pairs[k].a) << 32) | pairs[k].b, PairOrder{});
      for (const Contact& c : pairContacts[k]) {
        makeContact(bodies, pairs[k], a, b, c, cached, settings, dt, contacts_[slot], extras_[slot]);
        ++slot;
      }
    }
  });
}

void ContactSolver::loadBodies(const BodyStore& bodies, JobSystem& jobs, Profiler& profiler, int stage) {
  const uint32_t n = bodies.size();
  bodies_.resize(n);
  jobs.parallelFor(0, n, tuning::bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "solver: load bodies", stage);
    for (uint32_t i = begin; i < end; ++i)
      bodies_[i] = {bodies.linearVelocity[i], bodies.inverseMass[i], bodies.angularVelocity[i],
                    bodies.motion[i] == MotionType::Dynamic ? 1u : 0u};
  });
}

void ContactSolver::storeBodies(BodyStore& bodies, JobSystem& jobs, Profiler& profiler, int stage) const {
  const uint32_t n = bodies.size();
  jobs.parallelFor(0, n, tuning::bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "solver: store bodies", stage);
    for (uint32_t i = begin; i < end; ++i) {
      if (!bodies_[i].dynamic) continue;
      bodies.linearVelocity[i] = bodies_[i].v;
      bodies.angularVelocity[i] = bodies_[i].w;
    }
  });
}

void ContactSolver::warmStart(const SolverContact& s, SolverBody& a, SolverBody& b) { warmStartContact(s, a, b); }

// One Gauss-Seidel update of one contact (world/contact_update.h), then its rolling resistance.
void ContactSolver::solveContact(uint32_t k, bool relax, SolverBody& a, SolverBody& b) {
  SolverContact& s = contacts_[k];
  updateContact(s, relax, a, b);
  if (s.rolling > 0.f) resistRolling(s, extras_[k], a, b);
}

// Shock propagation (Guendelman et al.): after the iterations, one sweep from the bottom of the
// pile up in which each contact treats its lower body as immovable, so a heavy body cannot push
// a light one below it into the ground (the 1000:1 mass-ratio stack). Only the upper body's
// velocity changes; the accumulated impulses keep their clamps.
void ContactSolver::solveContactShock(uint32_t k) {
  SolverContact& s = contacts_[k];
  const SolverContactExtras& x = extras_[k];
  SolverBody& a = bodies_[s.a];
  SolverBody& b = bodies_[s.b];
  SolverBody& upper = x.shockLower == 1 ? b : a;
  auto relative = [&] { return Vec3f(a.v + a.w.cross(s.rA) - b.v - b.w.cross(s.rB)); };
  // Impulse along dir on the upper body only (a receives +, b receives -).
  auto push = [&](int d, const Vec3f& dir, float lambda) {
    if (x.shockLower == 1) {
      upper.v -= dir * (lambda * upper.invMass);
      upper.w -= s.angB[d] * lambda;
    } else {
      upper.v += dir * (lambda * upper.invMass);
      upper.w += s.angA[d] * lambda;
    }
  };
  const float oldN = s.lambdaN;
  s.lambdaN = std::max(oldN + x.shockMass[0] * (s.bias - relative().dot(s.normal)), 0.f);
  push(0, s.normal, s.lambdaN - oldN);
  const float limit = s.friction * s.lambdaN;
  const Vec3f v = relative();
  const float o1 = s.lambdaT1, o2 = s.lambdaT2;
  clampToFrictionCone(o1 - x.shockMass[1] * v.dot(s.t1), o2 - x.shockMass[2] * v.dot(s.t2), limit, s.lambdaT1, s.lambdaT2);
  push(1, s.t1, s.lambdaT1 - o1);
  push(2, s.t2, s.lambdaT2 - o2);
}

// The island's contacts bottom-up (by the lower body's height, ties by index: deterministic):
// contacts with a static or kinematic body first (they are the ground), then dynamic pairs.
void ContactSolver::shockSweep(std::vector<uint32_t>& list) {
  std::stable_sort(list.begin(), list.end(), [&](uint32_t x, uint32_t y) {
    const SolverContactExtras& p = extras_[x];
    const SolverContactExtras& q = extras_[y];
    if ((p.shockLower == 0) != (q.shockLower == 0)) return p.shockLower == 0;
    return p.height < q.height;
  });
  for (uint32_t k : list) {
    if (extras_[k].shockLower)
      solveContactShock(k);
    else
      solveContact(k, false);  // against the ground (or side by side): a normal update
  }
}


void ContactSolver::solveIsland(std::span<const uint32_t> island, bool relax, const SceneSettings& settings) {
  const uint32_t n = uint32_t(island.size());
  if (!relax)
    for (uint32_t k : island) warmStart(contacts_[k]);
  const int iterations = relax ? settings.relaxIterations : settings.solverIterations;
  for (int it = 0; it < iterations; ++it) {
    // note: sweeps alternate direction (symmetric Gauss-Seidel) so no contact is always solved
    // last; a fixed order makes friction in stacks creep one way.
    for (uint32_t j = 0; j < n; ++j) solveContact(island[(it & 1) ? n - 1 - j : j], relax);
  }
  if (!relax && settings.shockPropagation) {
    thread_local std::vector<uint32_t> list;  // note: per worker thread, reused across islands
    list.assign(island.begin(), island.end());
    shockSweep(list);
  }
}

// A job's islands in the lanes of IslandLanes (the same bits as one by one): a larger island
// regrouped by level on its own when that fills the lanes (a pile), the rest kLanes at a time,
// largest first so that the islands sharing the lanes are of similar sizes. Islands left alone,
// or among much smaller ones, are solved on their own (lanes pay only once enough of them are
// busy: IslandLanes::kMinContactsPerRow).
void ContactSolver::solveIslandsInLanes(const Islands& islands, std::span<const uint32_t> which, bool relax,
                                        const SceneSettings& settings) {
  thread_local IslandLanes lanes;            // note: per worker thread, rows reused across jobs
  thread_local std::vector<uint32_t> order;  // the job's islands to solve side by side, largest first
  thread_local std::vector<uint32_t> list;
  const int iterations = relax ? settings.relaxIterations : settings.solverIterations;
  const auto shock = [&](std::span<const uint32_t> island) {
    if (relax || !settings.shockPropagation) return;
    list.assign(island.begin(), island.end());
    shockSweep(list);
  };
  order.clear();
  for (uint32_t i : which) {
    const std::span<const uint32_t> island = islands.contacts(i);
    if (IslandLanes::kSimd && island.size() >= kLaneRegroupContacts &&
        lanes.solveOne(island, contacts_, extras_, bodies_, !relax, relax, iterations)) {
      shock(island);
      continue;
    }
    order.push_back(i);
  }
  // note: ties by island index (a total order: std::sort, where std::stable_sort asks the heap
  // for a buffer on every call).
  std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
    const size_t sx = islands.contacts(x).size(), sy = islands.contacts(y).size();
    return sx > sy || (sx == sy && x < y);
  });
  for (size_t g = 0; g < order.size(); g += IslandLanes::kLanes) {
    const size_t count = std::min<size_t>(IslandLanes::kLanes, order.size() - g);
    std::span<const uint32_t> group[IslandLanes::kLanes];
    size_t total = 0;
    for (size_t l = 0; l < count; ++l) total += (group[l] = islands.contacts(order[g + l])).size();
    if (!IslandLanes::kSimd || total < group[0].size() * IslandLanes::kMinContactsPerRow) {
      for (size_t l = 0; l < count; ++l) solveIsland(group[l], relax, settings);
      continue;
    }
    lanes.solve(std::span<const std::span<const uint32_t>>(group, count), contacts_, extras_, bodies_, !relax, relax, iterations);
    for (size_t l = 0; l < count; ++l) shock(group[l]);
  }
}

namespace {

// A profiling stage of its own for each wave of a coloured island: the colours run one after
// another, so work/span must add their spans, not fold them into the stage of the parallel
// islands. Distinct from every world stage (those stay below kWaveStageBase) within a frame.
constexpr int32_t kWaveStageBase = 1 << 20;
constexpr uint32_t kWavesPerStage = 1 << 16;
int32_t waveStage(int stage, uint32_t& wave) { return kWaveStageBase + stage * int32_t(kWavesPerStage) + int32_t(wave++ % kWavesPerStage); }

}  // namespace

// One big island (a pile) on every thread: colour by colour, each colour's contacts in parallel.
// Iterations alternate the colour order like solveIsland alternates the contact order.
void ContactSolver::solveIslandInColours(std::span<const uint32_t> island, uint32_t split, bool coloured,
                                         const std::vector<MotionType>& motion, bool relax, const SceneSettings& settings,
                                         JobSystem& jobs, Profiler& profiler, int stage, uint32_t& wave) {
  IslandColouring& colouring = colourings_[split];
  const char* const name = relax ? "relax: colour" : "colour";
  if (!coloured) {
    IslandColouring::ColouringStages stages;
    stages.points = waveStage(stage, wave);  // in this order: each call takes the next id
    stages.cells = waveStage(stage, wave);
    stages.colours = waveStage(stage, wave);
    stages.seen = waveStage(stage, wave);
    stages.owners = waveStage(stage, wave);
    stages.lists = waveStage(stage, wave);
    stages.slots = waveStage(stage, wave);
    stages.place = waveStage(stage, wave);
    stages.cleared = waveStage(stage, wave);
    colouring.colour(island, contacts_, motion, extras_, jobs, profiler, relax ? "relax: colouring" : "colouring", stages);
  }
  const uint32_t colours = colouring.colours();
  // Every pass over the colours in order, as waves of one parallel region: each colour's
  // contacts in parallel (no two share a dynamic body), the serial group as one chunk. A
  // wave starts when the one before has finished, as a fork-join per colour would, without
  // a fork-join's wake and wait per colour (which made chunks finer than 64 contacts cost
  // more than they saved on two threads; world_tuning.h).
  std::vector<ColourWave>& waves = waves_;
  std::vector<uint32_t>& chunks = waveChunks_;
  waves.clear();
  chunks.clear();
  const int32_t slotsInStage = waveStage(stage, wave);
  // A colour in chunks of one size, as many for every thread (each thread's slice of a wave is
  // the same number of chunks): a wave ends with its last chunk, and whole kColourGrain chunks
  // gave one thread a chunk more than another in most waves (crate_pile on two threads: ~100 us
  // of waiting in a frame's relax pass of ~420 us).
  const uint32_t members = uint32_t(jobs.threadCount());
  // A colour's contacts share no dynamic body: with lanes, kLanes of them a row (chunks of whole
  // rows), laid out in the colour's first wave of this solve and written back in its last.
  constexpr bool kLanes = IslandLanes::kSimd;
  constexpr uint32_t kRow = IslandLanes::kLanes;
  const int iterations = relax ? settings.relaxIterations : settings.solverIterations;
  const int passes = iterations + (relax ? 0 : 1);
  int passIndex = 0;
  const auto pass = [&](bool warmStart, bool reversed) {
    for (uint32_t i = 0; i < colours; ++i) {
      const uint32_t c = reversed ? colours - 1 - i : i;
      const uint32_t size = uint32_t(colouring.colour(c).size());
      uint32_t chunkSize = std::max(size, 1u);  // the serial group: one chunk
      if (c != kMaxColours) {
        const uint32_t perMember = (size + members * kColourGrain - 1) / (members * kColourGrain);
        chunkSize = std::max(kMinColourChunk, (size + members * perMember - 1) / std::max(members * perMember, 1u));
        if (kLanes) chunkSize = (chunkSize + kRow - 1) / kRow * kRow;
      }
      waves.push_back({c, waveStage(stage, wave), warmStart, chunkSize, passIndex == 0, passIndex == passes - 1});
      chunks.push_back(JobSystem::chunkCount(0, size, chunkSize));
    }
    ++passIndex;
  };
  // note: colour by colour, each body gets its contacts' warm-start impulses in the order of
  // colouring.all(), as a serial pass over it would: the result is the same.
  if (!relax) pass(true, false);
  for (int it = 0; it < iterations; ++it) pass(false, it & 1);
  IslandLanes::Rows& rows = colourRows_[split];
  std::vector<uint32_t>& rowStart = colourRowStart_[split];
  if (kLanes) {
    rowStart.assign(colours + 1, 0);
    for (uint32_t c = 0; c < colours; ++c) {
      const uint32_t size = c == kMaxColours ? 0 : uint32_t(colouring.colour(c).size());
      rowStart[c + 1] = rowStart[c] + (size + kRow - 1) / kRow;
    }
    rows.reserve(rowStart[colours]);
  }
  // The island's bodies into their slots, and back once the waves are done, in parallel (one
  // thread copying crate_pile's pile in and out was 10 us a pass, serial).
  const std::vector<uint32_t>& slotBodies = colouring.slotBodies();
  const uint32_t slotCount = uint32_t(slotBodies.size());
  const uint32_t slotGrain = tuning::grainFor(slotCount, kMinSlotCopyGrain);
  slots_.resize(slotCount);
  jobs.parallelFor(0, slotCount, slotGrain, [&](uint32_t begin, uint32_t end) {
    ProfileZone zone(profiler, "colour: slots in", slotsInStage);
    for (uint32_t i = begin; i < end; ++i)
      if (slotBodies[i] != kInvalidIndex) slots_[i] = bodies_[slotBodies[i]];
  });
  jobs.parallelWaves(chunks, [&](uint32_t w, uint32_t chunk) {
    const ColourWave& v = waves[w];
    const std::span<const uint32_t> group = colouring.colour(v.colour);
    const std::span<const IslandColouring::SlotPair> slots = colouring.slotPairs(v.colour);
    const bool serial = v.colour == kMaxColours;  // the serial group: contacts may share bodies
    const uint32_t begin = chunk * v.chunkSize;
    const uint32_t end = std::min(uint32_t(group.size()), begin + v.chunkSize);
    ProfileZone zone(profiler, v.warmStart ? "warm start" : name, v.stageId, serial);
    if constexpr (kLanes) {
      if (!serial) {
        // The chunk's rows: contacts begin .. end of the colour, kRow a row (the last may idle lanes).
        const uint32_t first = rowStart[v.colour] + begin / kRow, last = rowStart[v.colour] + (end + kRow - 1) / kRow;
        const auto laneSlots = [&](uint32_t r, uint32_t (&contact)[kRow], uint32_t (&a)[kRow], uint32_t (&b)[kRow]) {
          for (uint32_t l = 0; l < kRow; ++l) {
            const uint32_t j = (r - rowStart[v.colour]) * kRow + l;
            const bool in = j < end;
            contact[l] = in ? group[j] : IslandLanes::kNone;
            a[l] = in ? slots[j].a : IslandLanes::kIdleBody;
            b[l] = in ? slots[j].b : IslandLanes::kIdleBody;
          }
        };
        uint32_t contact[kRow], a[kRow], b[kRow];
        if (v.fill)
          for (uint32_t r = first; r < last; ++r) {
            laneSlots(r, contact, a, b);
            rows.fill(r, contact, a, b, contacts_, extras_, relax);
          }
        if (v.warmStart) rows.warmStart(first, last, slots_.data());
        else rows.pass(first, last, false, slots_.data());
        if (v.writeBack)
          for (uint32_t r = first; r < last; ++r) {
            laneSlots(r, contact, a, b);
            rows.writeBack(r, contact, contacts_, extras_);
          }
        return;
      }
    }
    for (uint32_t j = begin; j < end; ++j) {
      SolverBody& a = slots_[slots[j].a];
      SolverBody& b = slots_[slots[j].b];
      if (v.warmStart)
        warmStart(contacts_[group[j]], a, b);
      else
        solveContact(group[j], relax, a, b);
    }
  });
  const int32_t slotsOutStage = waveStage(stage, wave);
  jobs.parallelFor(0, slotCount, slotGrain, [&](uint32_t begin, uint32_t end) {
    ProfileZone zone(profiler, "colour: slots out", slotsOutStage);
    for (uint32_t i = begin; i < end; ++i)
      if (slotBodies[i] != kInvalidIndex && slots_[i].dynamic) bodies_[slotBodies[i]] = slots_[i];
  });
  if (!relax && settings.shockPropagation) {  // one serial sweep over the whole pile
    ProfileZone zone(profiler, "shock sweep", waveStage(stage, wave), true);
    std::vector<uint32_t> list(colouring.all().begin(), colouring.all().end());
    shockSweep(list);
  }
}

void ContactSolver::planIslands(const Islands& islands) {
  smallIslands_.clear();
  splitIslands_.clear();
  largestIsland_ = 0;
  uint64_t smallContacts = 0;
  for (uint32_t i = 0; i < islands.count(); ++i) {
    const uint32_t size = islands.size(i);
    largestIsland_ = std::max(largestIsland_, size);
    if (size > kSplitContacts) {
      splitIslands_.push_back(i);
    } else {
      smallIslands_.push_back(i);
      smallContacts += size;
    }
  }
  // Jobs of consecutive islands holding about 1/kTargetJobs of their contacts each (at least
  // kMinIslandJobContacts); an island that alone reaches that is a job of its own, so the
  // stage's span stays its largest island. (Which islands share a job changes no result.)
  const uint64_t perJob = std::max<uint64_t>(kMinIslandJobContacts, (smallContacts + tuning::kTargetJobs - 1) / tuning::kTargetJobs);
  islandJobStart_.clear();
  uint64_t inJob = 0;
  for (uint32_t k = 0; k < smallIslands_.size(); ++k) {
    const uint64_t size = islands.size(smallIslands_[k]);
    if (k == 0 || inJob + size > perJob) {
      islandJobStart_.push_back(k);
      inJob = 0;
    }
    inJob += size;
  }
  islandJobStart_.push_back(uint32_t(smallIslands_.size()));
}

SolveStats ContactSolver::solve(const Islands& islands, const std::vector<MotionType>& motion, bool relax,
                                const SceneSettings& settings, JobSystem& jobs, Profiler& profiler, int stage) {
  // Islands touch disjoint dynamic bodies: solving them in parallel is race-free and gives the
  // same result as solving them one by one. Islands above kSplitContacts are split by colour
  // instead (first, one at a time, each on every thread); which islands are split depends only
  // on their size, so the result does not depend on the thread count.
  // The relax pass solves the same islands over the same contacts: it reuses their colourings,
  // and the plan below (two serial passes over the islands: 7-8 us a substep on crates_on_grid's
  // ~1,000, in the work/span bound's serial glue).
  const bool reuse = relax && coloured_;
  if (!reuse) planIslands(islands);
  SolveStats stats;
  stats.largestIsland = largestIsland_;
  uint32_t wave = 0;
  for (uint32_t i : splitIslands_) {
    if (stats.splitIslands == colourings_.size()) {
      colourings_.emplace_back();
      colourRows_.emplace_back();
      colourRowStart_.emplace_back();
    }
    solveIslandInColours(islands.contacts(i), stats.splitIslands, reuse, motion, relax, settings, jobs, profiler,
                         stage + (relax ? 5 : 3), wave);
    ++stats.splitIslands;
  }
  jobs.parallelFor(0, uint32_t(islandJobStart_.size() - 1), 1, [&](uint32_t b, uint32_t e) {
    ProfileZone zone(profiler, relax ? "relax" : "island", stage + (relax ? 5 : 3));
    solveIslandsInLanes(islands, std::span<const uint32_t>(smallIslands_).subspan(islandJobStart_[b], islandJobStart_[e] - islandJobStart_[b]),
                        relax, settings);
  });
  coloured_ = !relax;
  return stats;
}

void ContactSolver::keepImpulses(JobSystem& jobs, Profiler& profiler, int stage) {
  const uint32_t n = uint32_t(contacts_.size());
  resizeForOverwrite(nextCache_, n);
  if (pairsInKeyOrder_) {
    // The pairs come in key order (the broadphase sorts them), each pair's contacts in its own
    // range: sorting each range by feature gives the list a stable sort of the whole by pair and
    // feature gives (the contact's index breaks ties). A pair holds a few contacts: on ship_refit
    // (traced) the copy and the whole sort took 0.9 ms a frame, the copy with these sorts 0.23.
    const uint32_t pairCount = uint32_t(first_.size()) - 1;
    jobs.parallelFor(0, pairCount, tuning::grainFor(pairCount, kMinPrepareGrain), [&](uint32_t begin, uint32_t end) {
      ProfileZone zone(profiler, "solver: keep impulses", stage);
      for (uint32_t k = begin; k < end; ++k) {
        for (uint32_t i = first_[k]; i < first_[k + 1]; ++i) nextCache_[i] = cachedImpulse(i);
        const auto from = nextCache_.begin() + first_[k], to = nextCache_.begin() + first_[k + 1];
        if (!std::is_sorted(from, to, CacheOrder{})) std::sort(from, to, CacheOrder{});
      }
    });
    std::swap(cache_, nextCache_);
    return;
  }
  // Otherwise the copy notes whether the contacts already come in pair and feature order; if
  // not, a sample sort of the whole. The contact's index breaks ties, so either way the list is
  // what a stable sort by pair and feature gives.
  const uint32_t grain = std::max(1024u, (n + 63) / 64);
  cacheChunkSorted_.assign(JobSystem::chunkCount(0, n, grain), 1);
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
    ProfileZone zone(profiler, "solver: keep impulses", stage);
    bool sorted = true;
    for (uint32_t i = begin; i < end; ++i) {
      nextCache_[i] = cachedImpulse(i);
      if (i > 0) {
        const SolverContactExtras& p = extras_[i - 1];
        const SolverContactExtras& s = extras_[i];
        sorted &= p.pairKey < s.pairKey || (p.pairKey == s.pairKey && p.feature <= s.feature);
      }
    }
    cacheChunkSorted_[begin / grain] = sorted;
  });
  if (std::find(cacheChunkSorted_.begin(), cacheChunkSorted_.end(), 0) != cacheChunkSorted_.end())
    cacheSorter_.sort(nextCache_, false, jobs, &profiler, "solver: sort impulses", stage + 1);
  std::swap(cache_, nextCache_);
}

CachedImpulse ContactSolver::cachedImpulse(uint32_t i) const {
  const SolverContact& s = contacts_[i];
  const SolverContactExtras& x = extras_[i];
  return {x.pairKey, x.feature, i, x.point, s.lambdaN, s.lambdaT1, s.lambdaT2};
}

}  // namespace bw
