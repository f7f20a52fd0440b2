#pragma once
/// Small islands solved four at a time, one island per SSE lane, with the bits of solving each
/// alone (world/contact_update.h's scalar reference).
///
///   IslandLanes lanes;  // one per thread: its rows are reused from call to call
///   const std::span<const uint32_t> four[] = {islandA, islandB, islandC, islandD};
///   lanes.solve(four, contacts, extras, bodies, /*warmStart*/ true, /*relax*/ false, iterations);
///
/// Why it gives the same bits: a Gauss-Seidel solve's result depends only on the order in which
/// each body receives its contacts' updates. Islands share no dynamic body, so solving four
/// side by side, each lane taking its own island's contacts in its own order, leaves every body
/// with the same sequence of float operations as solving the islands one after another. Each
/// lane does the scalar code's operations in the scalar code's order (products and sums lane by
/// lane, 3-vector dot products summed x + (y + z), std::max and the cone's select written as
/// compares, so a -0 or a NaN comes out as the scalar code's does; -ffp-contract=off), and a
/// body that is not dynamic is never written. Why it pays: one contact update is ~200
/// instructions of dependent scalar-width work; four in the lanes of one register cost little
/// more than one (ship_refit solves ~6,600 contacts in ~2,000 islands of at most 18, ten
/// passes a substep).
///
/// A pass runs the rows of the four islands in lockstep: row r holds contact r of each island.
/// Forward passes take rows 0, 1, ...; reversed passes (the alternate ones of symmetric
/// Gauss-Seidel) take rows M-1, M-2, ... where M is the longest island's size, so a shorter
/// island's lane idles through the rows past its end first and then runs its own contacts from
/// its last to its first, as solving it alone would. Islands of similar sizes waste the least.
#include <cstdint>
#include <span>
#include <vector>

#include "world/solver_contact.h"

namespace bw {

class IslandLanes {
 public:
  static constexpr uint32_t kLanes = 4;
  /// Whether this build solves in lanes (SSE2, every x86-64); without it solve() takes the
  /// islands one by one through the scalar reference.
  static constexpr bool kSimd =
#if defined(__SSE2__)
      true;
#else
      false;
#endif

  /// Solves up to kLanes islands (each a list of contact indices in its solve order; no two
  /// islands share a dynamic body): the warm start when warmStart, then `iterations` passes
  /// alternating direction, each contact followed by its rolling resistance when it rolls;
  /// relax: relaxBias instead of bias. The contacts' impulses (and rolling impulses) and the
  /// dynamic bodies' velocities end as solving each island alone would leave them, bit for bit.
  void solve(std::span<const std::span<const uint32_t>> islands, std::span<SolverContact> contacts,
             std::span<SolverContactExtras> extras, std::span<SolverBody> bodies, bool warmStart, bool relax, int iterations);

 private:
  /// Contact r of each island, field by field (lane l is island l's): what a pass reads. An
  /// idle lane holds zeros and a static body, so its arithmetic stays finite and writes nothing.
  struct alignas(16) Row {
    float n[3][4], bias[4], friction[4];
    float rA[3][4], rB[3][4], t1[3][4], t2[3][4];
    float angA[3][3][4], angB[3][3][4];  // [direction: n, t1, t2][axis][lane]
    float mass[3][4], lambda[3][4];      // [direction][lane]
    uint32_t a[4], b[4];                 // body indices; kIdleBody in an idle lane
    uint32_t rolls;                      // lanes whose contact rolls (rolling > 0), one bit each
  };
  /// The rolling resistance of a row's contacts (filled for rows where some lane rolls).
  struct alignas(16) RollRow {
    float rolling[4], lambdaR[2][4], massR[2][4];
    float rollA[2][3][4], rollB[2][3][4];  // [tangent][axis][lane]
  };
  static constexpr uint32_t kIdleBody = 0xFFFFFFFFu;

  void fillRows(std::span<const std::span<const uint32_t>> islands, std::span<const SolverContact> contacts,
                std::span<const SolverContactExtras> extras, bool relax, uint32_t longest);
  void warmStartRow(const Row& row, SolverBody* bodies) const;
  void updateRow(Row& row, RollRow* roll, SolverBody* bodies) const;

  std::vector<Row> rows_;
  std::vector<RollRow> roll_;
};

}  // namespace bw
