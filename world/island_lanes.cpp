#include "world/island_lanes.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

#include "collision/core/assert.h"
#include "world/contact_update.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bw {

// The kernels read SolverBody records as eight floats: v, invMass, w, the dynamic word.
static_assert(sizeof(SolverBody) == 8 * sizeof(float));
static_assert(offsetof(SolverBody, v) == 0 && offsetof(SolverBody, invMass) == 12 && offsetof(SolverBody, w) == 16 &&
              offsetof(SolverBody, dynamic) == 28);

void IslandLanes::Rows::reserve(uint32_t count) {
  if (count <= capacity_) return;
  // note: default-initialised (no zeroing): fill() writes every field of every lane it lays out.
  // Grown by half again at least, so a frame whose islands grow a little allocates nothing.
  const uint32_t grown = std::max(count, capacity_ + capacity_ / 2);
  rows_.reset(new Row[grown]);
  roll_.reset(new RollRow[grown]);
  capacity_ = grown;
}

namespace {

// Where each float of a SolverContact record goes in a row (in floats from the row's start, lane
// 0), or -1: the transposed fill below moves a record's 16-byte blocks into the row's fields.
constexpr int kRecordFloats = int(sizeof(SolverContact) / sizeof(float));
struct RecordMap {
  int16_t at[kRecordFloats];
};
constexpr RecordMap recordMap(bool relax) {
  using lanes::Row;
  constexpr int16_t w = int16_t(lanes::kWidth);
  const auto in = [](size_t bytes) { return int16_t(bytes / sizeof(float)); };
  RecordMap m{};
  for (int16_t& x : m.at) x = -1;
  for (int k = 0; k < 3; ++k) {
    m.at[in(offsetof(SolverContact, normal)) + k] = int16_t(in(offsetof(Row, n)) + k * w);
    m.at[in(offsetof(SolverContact, rA)) + k] = int16_t(in(offsetof(Row, rA)) + k * w);
    m.at[in(offsetof(SolverContact, rB)) + k] = int16_t(in(offsetof(Row, rB)) + k * w);
    m.at[in(offsetof(SolverContact, t1)) + k] = int16_t(in(offsetof(Row, t1)) + k * w);
    m.at[in(offsetof(SolverContact, t2)) + k] = int16_t(in(offsetof(Row, t2)) + k * w);
    for (int d = 0; d < 3; ++d) {
      m.at[in(offsetof(SolverContact, angA)) + 3 * d + k] = int16_t(in(offsetof(Row, angA)) + (3 * d + k) * w);
      m.at[in(offsetof(SolverContact, angB)) + 3 * d + k] = int16_t(in(offsetof(Row, angB)) + (3 * d + k) * w);
    }
  }
  m.at[in(relax ? offsetof(SolverContact, relaxBias) : offsetof(SolverContact, bias))] = in(offsetof(Row, bias));
  m.at[in(offsetof(SolverContact, friction))] = in(offsetof(Row, friction));
  m.at[in(offsetof(SolverContact, massN))] = in(offsetof(Row, mass));
  m.at[in(offsetof(SolverContact, massT1))] = int16_t(in(offsetof(Row, mass)) + w);
  m.at[in(offsetof(SolverContact, massT2))] = int16_t(in(offsetof(Row, mass)) + 2 * w);
  m.at[in(offsetof(SolverContact, lambdaN))] = in(offsetof(Row, lambda));
  m.at[in(offsetof(SolverContact, lambdaT1))] = int16_t(in(offsetof(Row, lambda)) + w);
  m.at[in(offsetof(SolverContact, lambdaT2))] = int16_t(in(offsetof(Row, lambda)) + 2 * w);
  return m;
}
constexpr RecordMap kSolveMap = recordMap(false), kRelaxMap = recordMap(true);
static_assert(sizeof(SolverContact) % 16 == 0 && alignof(SolverContact) >= 16);

// An idle lane's record: zeros.
alignas(64) const float kZeroRecord[kRecordFloats] = {};

// Lanes off .. off + 3 of a row from four records, their fields as the row lays them out.
void fillFour(float* row, uint32_t off, const float* const* record, const RecordMap& map) {
#if defined(__SSE2__)
  for (int block = 0; block < kRecordFloats; block += 4) {
    __m128 r0 = _mm_load_ps(record[0] + block), r1 = _mm_load_ps(record[1] + block), r2 = _mm_load_ps(record[2] + block),
           r3 = _mm_load_ps(record[3] + block);
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    const __m128 columns[4] = {r0, r1, r2, r3};
    for (int j = 0; j < 4; ++j)
      if (map.at[block + j] >= 0) _mm_store_ps(row + map.at[block + j] + off, columns[j]);
  }
#else
  for (int i = 0; i < kRecordFloats; ++i)
    if (map.at[i] >= 0)
      for (int l = 0; l < 4; ++l) row[map.at[i] + off + l] = record[l][i];
#endif
}

}  // namespace

void IslandLanes::Rows::fill(uint32_t r, const uint32_t* slots, const uint32_t* a, const uint32_t* b,
                             std::span<const SolverContact> contacts, std::span<const SolverContactExtras> extras, bool relax) {
  BW_ASSERT(r < capacity_);
  Row& row = rows_[r];
  row.rolls = row.active = 0;
  const float* record[kLanes];
  for (uint32_t l = 0; l < kLanes; ++l) {
    if (slots[l] == kNone) {
      row.a[l] = row.b[l] = kIdleBody;
      record[l] = kZeroRecord;
      continue;
    }
    const SolverContact& s = contacts[slots[l]];
    record[l] = reinterpret_cast<const float*>(&s);
    row.active |= 1u << l;
    row.a[l] = a ? a[l] : s.a;
    row.b[l] = b ? b[l] : s.b;
    if (s.rolling > 0.f) row.rolls |= 1u << l;
  }
  float* const out = reinterpret_cast<float*>(&row);
  for (uint32_t off = 0; off < kLanes; off += 4) fillFour(out, off, record + off, relax ? kRelaxMap : kSolveMap);
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
                                std::span<const SolverBody> bodies) {
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
  slots_.assign(size_t(rows) * kLanes, kNone);
  for (uint32_t i = 0; i < n; ++i) slots_[levelStart_[levelOf_[i]]++] = order[i];
  return rows;
}

#if defined(__SSE2__)
void IslandLanes::Rows::warmStart(uint32_t first, uint32_t last, SolverBody* bodies) const {
  float* const records = reinterpret_cast<float*>(bodies);
  if (lanes::avx2()) lanes::warmStartAvx2(rows_.get(), first, last, records);
  else lanes::warmStartSse2(rows_.get(), first, last, records);
}

void IslandLanes::Rows::pass(uint32_t first, uint32_t last, bool reversed, SolverBody* bodies) {
  float* const records = reinterpret_cast<float*>(bodies);
  if (lanes::avx2()) lanes::passAvx2(rows_.get(), roll_.get(), first, last, reversed, records);
  else lanes::passSse2(rows_.get(), roll_.get(), first, last, reversed, records);
}
#endif

#if defined(__SSE2__)
// The rows in slots_ solved: laid out, the warm start, passes alternating direction (a reversed
// pass runs the rows last to first: see the header), the impulses back to their contacts.
void IslandLanes::runRows(uint32_t rows, std::span<SolverContact> contacts, std::span<SolverContactExtras> extras,
                          std::span<SolverBody> bodies, bool warmStart, bool relax, int iterations) {
  fillAll(rows_, slots_, contacts, extras, relax);
  if (warmStart) rows_.warmStart(0, rows, bodies.data());
  for (int it = 0; it < iterations; ++it) rows_.pass(0, rows, (it & 1) != 0, bodies.data());
  writeBackAll(rows_, slots_, contacts, extras);
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
  runRows(longest, contacts, extras, bodies, warmStart, relax, iterations);
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
  const uint32_t rows = levelRows(island, contacts, bodies);
  if (uint64_t(rows) * kMinContactsPerRow >= n) return false;
  runRows(rows, contacts, extras, bodies, warmStart, relax, iterations);
  return true;
#else
  (void)island, (void)contacts, (void)extras, (void)bodies, (void)warmStart, (void)relax, (void)iterations;
  return false;
#endif
}

}  // namespace bw
