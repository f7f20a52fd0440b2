#include "world/island_lanes.h"

#include <algorithm>
#include <cstring>

#include "collision/core/assert.h"
#include "world/contact_update.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bw {

#if defined(__SSE2__)
namespace {

// What an idle lane reads as its bodies: static and still.
const SolverBody kIdle{Vec3f::Zero(), 0.f, Vec3f::Zero(), 0u};

// Each operation below is the scalar reference's, lane by lane (see the header).
struct V3 {
  __m128 x, y, z;
};
inline __m128 load(const float (&f)[4]) { return _mm_load_ps(f); }
inline V3 load3(const float (&f)[3][4]) { return {_mm_load_ps(f[0]), _mm_load_ps(f[1]), _mm_load_ps(f[2])}; }
inline V3 add(V3 a, V3 b) { return {_mm_add_ps(a.x, b.x), _mm_add_ps(a.y, b.y), _mm_add_ps(a.z, b.z)}; }
inline V3 sub(V3 a, V3 b) { return {_mm_sub_ps(a.x, b.x), _mm_sub_ps(a.y, b.y), _mm_sub_ps(a.z, b.z)}; }
inline V3 mul(V3 a, __m128 s) { return {_mm_mul_ps(a.x, s), _mm_mul_ps(a.y, s), _mm_mul_ps(a.z, s)}; }
// m ? a : b, lane by lane (m all ones or all zeros).
inline __m128 select(__m128 m, __m128 a, __m128 b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }
inline V3 select(__m128 m, V3 a, V3 b) { return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)}; }
// Eigen's cross product: (a.y b.z - a.z b.y, a.z b.x - a.x b.z, a.x b.y - a.y b.x).
inline V3 cross(V3 a, V3 b) {
  return {_mm_sub_ps(_mm_mul_ps(a.y, b.z), _mm_mul_ps(a.z, b.y)), _mm_sub_ps(_mm_mul_ps(a.z, b.x), _mm_mul_ps(a.x, b.z)),
          _mm_sub_ps(_mm_mul_ps(a.x, b.y), _mm_mul_ps(a.y, b.x))};
}
// Eigen's dot product of 3-vectors: x + (y + z).
inline __m128 dot(V3 a, V3 b) {
  return _mm_add_ps(_mm_mul_ps(a.x, b.x), _mm_add_ps(_mm_mul_ps(a.y, b.y), _mm_mul_ps(a.z, b.z)));
}
// std::max(x, 0.f): x unless x < 0, so -0 and NaN come out as they went in.
inline __m128 maxZero(__m128 x) { return _mm_andnot_ps(_mm_cmplt_ps(x, _mm_setzero_ps()), x); }
// clampToFrictionCone: (t1, t2) scaled back to length `limit` when longer.
inline void clampToCone(__m128 t1, __m128 t2, __m128 limit, __m128& out1, __m128& out2) {
  const __m128 length2 = _mm_add_ps(_mm_mul_ps(t1, t1), _mm_mul_ps(t2, t2));
  const __m128 over = _mm_cmpgt_ps(length2, _mm_mul_ps(limit, limit));
  const __m128 scale = select(over, _mm_div_ps(limit, _mm_sqrt_ps(length2)), _mm_set1_ps(1.f));
  out1 = _mm_mul_ps(t1, scale);
  out2 = _mm_mul_ps(t2, scale);
}
// All ones in the lanes whose bit is set.
inline __m128 laneMask(uint32_t bits) {
  return _mm_castsi128_ps(_mm_set_epi32(-int((bits >> 3) & 1), -int((bits >> 2) & 1), -int((bits >> 1) & 1), -int(bits & 1)));
}

// One side (a or b) of a row's four contacts: the four bodies' velocity records transposed into
// lanes, and written back to the dynamic ones. A SolverBody is two 16-byte blocks, (v, invMass)
// and (w, dynamic): the transposes carry invMass and the dynamic word through unchanged.
struct LaneBodies {
  SolverBody* at[4];  // nullptr in an idle lane
  V3 v, w;
  __m128 invMass, dynamicWord, dynamic;  // dynamic: all ones where the body is dynamic
  __m128 stillNegZero;                   // -0 where a lane's body is not dynamic, else +0
  uint32_t dynamicBits;
  bool masked;  // some lane holds a real body that is not dynamic (idle lanes' results are dropped)

  LaneBodies(const uint32_t (&index)[4], uint32_t idle, SolverBody* bodies) {
    const float* in[4];
    for (int l = 0; l < 4; ++l) {
      at[l] = index[l] == idle ? nullptr : &bodies[index[l]];
      in[l] = (at[l] ? at[l] : &kIdle)->v.data();
    }
    __m128 r0 = _mm_loadu_ps(in[0]), r1 = _mm_loadu_ps(in[1]), r2 = _mm_loadu_ps(in[2]), r3 = _mm_loadu_ps(in[3]);
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    v = {r0, r1, r2};
    invMass = r3;
    __m128 s0 = _mm_loadu_ps(in[0] + 4), s1 = _mm_loadu_ps(in[1] + 4), s2 = _mm_loadu_ps(in[2] + 4), s3 = _mm_loadu_ps(in[3] + 4);
    _MM_TRANSPOSE4_PS(s0, s1, s2, s3);
    w = {s0, s1, s2};
    dynamicWord = s3;
    const __m128i still = _mm_cmpeq_epi32(_mm_castps_si128(s3), _mm_setzero_si128());
    dynamic = _mm_castsi128_ps(_mm_xor_si128(still, _mm_set1_epi32(-1)));
    stillNegZero = _mm_andnot_ps(dynamic, _mm_set1_ps(-0.f));
    dynamicBits = uint32_t(_mm_movemask_ps(dynamic));
    uint32_t real = 0;
    for (int l = 0; l < 4; ++l) real |= uint32_t(at[l] != nullptr) << l;
    masked = (real & ~dynamicBits) != 0;
  }
  // Impulse `lambda` along dir with angular response ang: + for side a, - for side b. A body
  // that is not dynamic keeps its velocity bits: it gains -0 (x + -0 == x for every x, +0 and
  // -0 included) or loses +0 (x - +0 == x), as the scalar code's `if (dynamic)` leaves it.
  template <bool kPlus>
  void apply(V3 dir, V3 ang, __m128 lambda) {
    const __m128 scaled = _mm_mul_ps(lambda, invMass);
    V3 dv = mul(dir, scaled), dw = mul(ang, lambda);
    if (masked) {
      if constexpr (kPlus) {
        dv = {_mm_or_ps(_mm_and_ps(dynamic, dv.x), stillNegZero), _mm_or_ps(_mm_and_ps(dynamic, dv.y), stillNegZero),
              _mm_or_ps(_mm_and_ps(dynamic, dv.z), stillNegZero)};
        dw = {_mm_or_ps(_mm_and_ps(dynamic, dw.x), stillNegZero), _mm_or_ps(_mm_and_ps(dynamic, dw.y), stillNegZero),
              _mm_or_ps(_mm_and_ps(dynamic, dw.z), stillNegZero)};
      } else {
        dv = {_mm_and_ps(dynamic, dv.x), _mm_and_ps(dynamic, dv.y), _mm_and_ps(dynamic, dv.z)};
        dw = {_mm_and_ps(dynamic, dw.x), _mm_and_ps(dynamic, dw.y), _mm_and_ps(dynamic, dw.z)};
      }
    }
    if constexpr (kPlus) {
      v = add(v, dv);
      w = add(w, dw);
    } else {
      v = sub(v, dv);
      w = sub(w, dw);
    }
  }
  void store() const {
    if (!dynamicBits) return;
    __m128 r0 = v.x, r1 = v.y, r2 = v.z, r3 = invMass;
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    __m128 s0 = w.x, s1 = w.y, s2 = w.z, s3 = dynamicWord;
    _MM_TRANSPOSE4_PS(s0, s1, s2, s3);
    const __m128 first[4] = {r0, r1, r2, r3}, second[4] = {s0, s1, s2, s3};
    for (int l = 0; l < 4; ++l) {
      if (!((dynamicBits >> l) & 1)) continue;
      float* out = at[l]->v.data();
      _mm_storeu_ps(out, first[l]);
      _mm_storeu_ps(out + 4, second[l]);
    }
  }
};

// The velocity of a's contact point relative to b's: ((vA + wA x rA) - vB) - wB x rB.
inline V3 relative(const LaneBodies& a, const LaneBodies& b, V3 rA, V3 rB) {
  return sub(sub(add(a.v, cross(a.w, rA)), b.v), cross(b.w, rB));
}

}  // namespace
#endif

void IslandLanes::Rows::reserve(uint32_t count) {
  if (count <= capacity_) return;
  // note: default-initialised (no zeroing): fill() writes every field of every lane it lays out.
  rows_.reset(new Row[count]);
  roll_.reset(new RollRow[count]);
  capacity_ = count;
}

void IslandLanes::Rows::fill(uint32_t r, const uint32_t* slots, const uint32_t* a, const uint32_t* b,
                             std::span<const SolverContact> contacts, std::span<const SolverContactExtras> extras, bool relax) {
  BW_ASSERT(r < capacity_);
  Row& row = rows_[r];
  row.rolls = 0;
  for (uint32_t l = 0; l < kLanes; ++l) {
    if (slots[l] == kNone) {
      row.a[l] = row.b[l] = kIdleBody;
      for (int k = 0; k < 3; ++k) {
        row.n[k][l] = row.rA[k][l] = row.rB[k][l] = row.t1[k][l] = row.t2[k][l] = 0.f;
        row.mass[k][l] = row.lambda[k][l] = 0.f;
        for (int d = 0; d < 3; ++d) row.angA[d][k][l] = row.angB[d][k][l] = 0.f;
      }
      row.bias[l] = row.friction[l] = 0.f;
      continue;
    }
    const SolverContact& s = contacts[slots[l]];
    row.a[l] = a ? a[l] : s.a;
    row.b[l] = b ? b[l] : s.b;
    for (int k = 0; k < 3; ++k) {
      row.n[k][l] = s.normal[k];
      row.rA[k][l] = s.rA[k];
      row.rB[k][l] = s.rB[k];
      row.t1[k][l] = s.t1[k];
      row.t2[k][l] = s.t2[k];
      for (int d = 0; d < 3; ++d) {
        row.angA[d][k][l] = s.angA[d][k];
        row.angB[d][k][l] = s.angB[d][k];
      }
    }
    row.bias[l] = relax ? s.relaxBias : s.bias;
    row.friction[l] = s.friction;
    row.mass[0][l] = s.massN;
    row.mass[1][l] = s.massT1;
    row.mass[2][l] = s.massT2;
    row.lambda[0][l] = s.lambdaN;
    row.lambda[1][l] = s.lambdaT1;
    row.lambda[2][l] = s.lambdaT2;
    if (s.rolling > 0.f) row.rolls |= 1u << l;
  }
  if (!row.rolls) return;
  RollRow& roll = roll_[r];
  for (uint32_t l = 0; l < kLanes; ++l) {
    const bool rolls = (row.rolls >> l) & 1;
    const SolverContactExtras* x = rolls ? &extras[slots[l]] : nullptr;
    roll.rolling[l] = rolls ? contacts[slots[l]].rolling : 0.f;
    roll.lambdaR[0][l] = rolls ? x->lambdaR1 : 0.f;
    roll.lambdaR[1][l] = rolls ? x->lambdaR2 : 0.f;
    for (int t = 0; t < 2; ++t) {
      roll.massR[t][l] = rolls ? x->massR[t] : 0.f;
      for (int k = 0; k < 3; ++k) {
        roll.rollA[t][k][l] = rolls ? x->rollA[t][k] : 0.f;
        roll.rollB[t][k][l] = rolls ? x->rollB[t][k] : 0.f;
      }
    }
  }
}

void IslandLanes::Rows::writeBack(uint32_t r, const uint32_t* slots, std::span<SolverContact> contacts,
                                  std::span<SolverContactExtras> extras) const {
  const Row& row = rows_[r];
  for (uint32_t l = 0; l < kLanes; ++l) {
    if (slots[l] == kNone) continue;
    SolverContact& s = contacts[slots[l]];
    s.lambdaN = row.lambda[0][l];
    s.lambdaT1 = row.lambda[1][l];
    s.lambdaT2 = row.lambda[2][l];
    if ((row.rolls >> l) & 1) {
      extras[slots[l]].lambdaR1 = roll_[r].lambdaR[0][l];
      extras[slots[l]].lambdaR2 = roll_[r].lambdaR[1][l];
    }
  }
}

void IslandLanes::Rows::carry(uint32_t from, Rows& other, uint32_t to) const {
  const Row& src = rows_[from / kLanes];
  Row& dst = other.rows_[to / kLanes];
  const uint32_t f = from % kLanes, t = to % kLanes;
  for (int d = 0; d < 3; ++d) dst.lambda[d][t] = src.lambda[d][f];
  if ((src.rolls >> f) & 1)
    for (int d = 0; d < 2; ++d) other.roll_[to / kLanes].lambdaR[d][t] = roll_[from / kLanes].lambdaR[d][f];
}

void IslandLanes::fillAll(Rows& rows, std::span<const uint32_t> slots, std::span<const SolverContact> contacts,
                          std::span<const SolverContactExtras> extras, bool relax) {
  const uint32_t count = uint32_t(slots.size() / kLanes);
  rows.reserve(count);
  for (uint32_t r = 0; r < count; ++r) rows.fill(r, &slots[size_t(r) * kLanes], nullptr, nullptr, contacts, extras, relax);
}

void IslandLanes::writeBackAll(const Rows& rows, std::span<const uint32_t> slots, std::span<SolverContact> contacts,
                               std::span<SolverContactExtras> extras) {
  for (uint32_t r = 0; r < uint32_t(slots.size() / kLanes); ++r) rows.writeBack(r, &slots[size_t(r) * kLanes], contacts, extras);
}

uint32_t IslandLanes::levelRows(std::span<const uint32_t> order, std::span<const SolverContact> contacts,
                                std::span<const SolverBody> bodies, std::vector<uint32_t>& out, std::vector<uint32_t>& at) {
  const uint32_t n = uint32_t(order.size());
  if (bodyLevel_.size() < bodies.size()) bodyLevel_.resize(bodies.size(), 0);
  levelOf_.resize(n);
  uint32_t levels = 0;
  for (uint32_t i = 0; i < n; ++i) {
    // note: only dynamic bodies order updates: the others are read, never written.
    const SolverContact& s = contacts[order[i]];
    const bool dynA = bodies[s.a].dynamic != 0, dynB = bodies[s.b].dynamic != 0;
    const uint32_t level = std::max(dynA ? bodyLevel_[s.a] : 0u, dynB ? bodyLevel_[s.b] : 0u);
    levelOf_[i] = level;
    if (dynA) bodyLevel_[s.a] = level + 1;
    if (dynB) bodyLevel_[s.b] = level + 1;
    levels = std::max(levels, level + 1);
  }
  for (uint32_t i = 0; i < n; ++i) bodyLevel_[contacts[order[i]].a] = bodyLevel_[contacts[order[i]].b] = 0;
  // Each level's contacts in the pass's order, kLanes a row; a level's last row may idle lanes.
  levelStart_.assign(levels + 1, 0);
  for (uint32_t i = 0; i < n; ++i) ++levelStart_[levelOf_[i] + 1];
  uint32_t rows = 0;
  for (uint32_t level = 0; level < levels; ++level) {
    const uint32_t size = levelStart_[level + 1];
    levelStart_[level + 1] = levelStart_[level] + (size + kLanes - 1) / kLanes * kLanes;  // slots, row aligned
    rows += (size + kLanes - 1) / kLanes;
  }
  out.assign(size_t(rows) * kLanes, kNone);
  at.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t slot = levelStart_[levelOf_[i]]++;
    out[slot] = order[i];
    at[i] = slot;
  }
  return rows;
}

#if defined(__SSE2__)
void IslandLanes::Rows::warmStart(uint32_t first, uint32_t last, SolverBody* bodies) const {
  for (uint32_t r = first; r < last; ++r) {
    const Row& row = rows_[r];
    LaneBodies a(row.a, kIdleBody, bodies), b(row.b, kIdleBody, bodies);
    const V3 dirs[3] = {load3(row.n), load3(row.t1), load3(row.t2)};
    for (int d = 0; d < 3; ++d) {
      const __m128 lambda = load(row.lambda[d]);
      a.apply<true>(dirs[d], load3(row.angA[d]), lambda);
      b.apply<false>(dirs[d], load3(row.angB[d]), lambda);
    }
    a.store();
    b.store();
  }
}

namespace {
// updateContact (then resistRolling where the lane's contact rolls), lane by lane.
template <class Row, class RollRow>
void updateRow(Row& row, RollRow* roll, SolverBody* bodies, uint32_t idle) {
  LaneBodies a(row.a, idle, bodies), b(row.b, idle, bodies);
  const V3 n = load3(row.n), rA = load3(row.rA), rB = load3(row.rB);
  const __m128 oldN = load(row.lambda[0]);
  const __m128 lambdaN =
      maxZero(_mm_add_ps(oldN, _mm_mul_ps(load(row.mass[0]), _mm_sub_ps(load(row.bias), dot(relative(a, b, rA, rB), n)))));
  const __m128 stepN = _mm_sub_ps(lambdaN, oldN);
  a.apply<true>(n, load3(row.angA[0]), stepN);
  b.apply<false>(n, load3(row.angB[0]), stepN);
  const __m128 limit = _mm_mul_ps(load(row.friction), lambdaN);
  const V3 v = relative(a, b, rA, rB);
  const V3 t1 = load3(row.t1), t2 = load3(row.t2);
  const __m128 o1 = load(row.lambda[1]), o2 = load(row.lambda[2]);
  __m128 lambdaT1, lambdaT2;
  clampToCone(_mm_sub_ps(o1, _mm_mul_ps(load(row.mass[1]), dot(v, t1))),
              _mm_sub_ps(o2, _mm_mul_ps(load(row.mass[2]), dot(v, t2))), limit, lambdaT1, lambdaT2);
  const __m128 step1 = _mm_sub_ps(lambdaT1, o1), step2 = _mm_sub_ps(lambdaT2, o2);
  a.apply<true>(t1, load3(row.angA[1]), step1);
  b.apply<false>(t1, load3(row.angB[1]), step1);
  a.apply<true>(t2, load3(row.angA[2]), step2);
  b.apply<false>(t2, load3(row.angB[2]), step2);
  _mm_store_ps(row.lambda[0], lambdaN);
  _mm_store_ps(row.lambda[1], lambdaT1);
  _mm_store_ps(row.lambda[2], lambdaT2);
  if (row.rolls) {
    // resistRolling on the bodies as the update left them; lanes that do not roll keep theirs.
    const __m128 rolls = laneMask(row.rolls);
    const V3 w = sub(a.w, b.w);
    const __m128 r1 = load(roll->lambdaR[0]), r2 = load(roll->lambdaR[1]);
    __m128 lambdaR1, lambdaR2;
    clampToCone(_mm_sub_ps(r1, _mm_mul_ps(load(roll->massR[0]), dot(w, t1))),
                _mm_sub_ps(r2, _mm_mul_ps(load(roll->massR[1]), dot(w, t2))), _mm_mul_ps(load(roll->rolling), lambdaN),
                lambdaR1, lambdaR2);
    const __m128 d1 = _mm_sub_ps(lambdaR1, r1), d2 = _mm_sub_ps(lambdaR2, r2);
    const V3 turnA = add(mul(load3(roll->rollA[0]), d1), mul(load3(roll->rollA[1]), d2));
    const V3 turnB = add(mul(load3(roll->rollB[0]), d1), mul(load3(roll->rollB[1]), d2));
    a.w = select(_mm_and_ps(rolls, a.dynamic), add(a.w, turnA), a.w);
    b.w = select(_mm_and_ps(rolls, b.dynamic), sub(b.w, turnB), b.w);
    _mm_store_ps(roll->lambdaR[0], select(rolls, lambdaR1, r1));
    _mm_store_ps(roll->lambdaR[1], select(rolls, lambdaR2, r2));
  }
  a.store();
  b.store();
}
}  // namespace

void IslandLanes::Rows::pass(uint32_t first, uint32_t last, bool reversed, SolverBody* bodies) {
  for (uint32_t j = first; j < last; ++j) {
    const uint32_t r = reversed ? first + last - 1 - j : j;
    updateRow(rows_[r], &roll_[r], bodies, kIdleBody);
  }
}
#endif

void IslandLanes::solve(std::span<const std::span<const uint32_t>> islands, std::span<SolverContact> contacts,
                        std::span<SolverContactExtras> extras, std::span<SolverBody> bodies, bool warmStart, bool relax,
                        int iterations) {
  BW_ASSERT(islands.size() <= kLanes);
#if defined(__SSE2__)
  uint32_t longest = 0;
  for (const std::span<const uint32_t>& island : islands) longest = std::max(longest, uint32_t(island.size()));
  if (longest == 0) return;
  slots_.assign(size_t(longest) * kLanes, kNone);
  for (uint32_t l = 0; l < uint32_t(islands.size()); ++l)
    for (uint32_t r = 0; r < uint32_t(islands[l].size()); ++r) slots_[size_t(r) * kLanes + l] = islands[l][r];
  fillAll(forward_, slots_, contacts, extras, relax);
  if (warmStart) forward_.warmStart(0, longest, bodies.data());
  // Reversed passes run the rows from the longest island's end (see the header).
  for (int it = 0; it < iterations; ++it) forward_.pass(0, longest, (it & 1) != 0, bodies.data());
  writeBackAll(forward_, slots_, contacts, extras);
#else
  // One island after another, as ContactSolver solves an island alone.
  for (const std::span<const uint32_t>& island : islands) {
    const uint32_t n = uint32_t(island.size());
    if (warmStart)
      for (uint32_t k : island) warmStartContact(contacts[k], bodies[contacts[k].a], bodies[contacts[k].b]);
    for (int it = 0; it < iterations; ++it)
      for (uint32_t j = 0; j < n; ++j) {
        const uint32_t k = island[(it & 1) ? n - 1 - j : j];
        updateContact(contacts[k], relax, bodies[contacts[k].a], bodies[contacts[k].b]);
        if (contacts[k].rolling > 0.f) resistRolling(contacts[k], extras[k], bodies[contacts[k].a], bodies[contacts[k].b]);
      }
  }
#endif
}

bool IslandLanes::solveOne(std::span<const uint32_t> island, std::span<SolverContact> contacts,
                           std::span<SolverContactExtras> extras, std::span<SolverBody> bodies, bool warmStart, bool relax,
                           int iterations) {
#if defined(__SSE2__)
  const uint32_t n = uint32_t(island.size());
  if (n == 0) return false;
  const uint32_t forwardRows = levelRows(island, contacts, bodies, slots_, forwardAt_);
  if (uint64_t(forwardRows) * kRowCostNum >= uint64_t(n) * kRowCostDen) return false;
  reversedOrder_.assign(island.rbegin(), island.rend());
  levelRows(reversedOrder_, contacts, bodies, backwardSlots_, backwardAt_);
  // backwardAt_ by the island's own positions, as forwardAt_ is.
  std::reverse(backwardAt_.begin(), backwardAt_.end());
  fillAll(forward_, slots_, contacts, extras, relax);
  fillAll(backward_, backwardSlots_, contacts, extras, relax);
  const uint32_t backwardRows = uint32_t(backwardSlots_.size() / kLanes);
  if (warmStart) forward_.warmStart(0, forwardRows, bodies.data());
  bool inForward = true;  // which rows hold the impulses as they now are
  for (int it = 0; it < iterations; ++it) {
    const bool forwardPass = (it & 1) == 0;
    if (forwardPass != inForward) {
      for (uint32_t p = 0; p < n; ++p) {
        if (forwardPass) backward_.carry(backwardAt_[p], forward_, forwardAt_[p]);
        else forward_.carry(forwardAt_[p], backward_, backwardAt_[p]);
      }
      inForward = forwardPass;
    }
    if (forwardPass) forward_.pass(0, forwardRows, false, bodies.data());
    else backward_.pass(0, backwardRows, false, bodies.data());
  }
  if (inForward) writeBackAll(forward_, slots_, contacts, extras);
  else writeBackAll(backward_, backwardSlots_, contacts, extras);
  return true;
#else
  (void)island, (void)contacts, (void)extras, (void)bodies, (void)warmStart, (void)relax, (void)iterations;
  return false;
#endif
}

}  // namespace bw
