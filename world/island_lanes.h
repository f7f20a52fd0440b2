#pragma once
/// Small islands solved eight at a time, one island per SIMD lane, with the bits of solving each
/// alone (world/contact_update.h's scalar reference).
///
///   IslandLanes lanes;  // one per thread: its rows are reused from call to call
///   const std::span<const uint32_t> some[] = {islandA, islandB, islandC};  // up to kLanes
///   lanes.solve(some, contacts, extras, bodies, /*warmStart*/ true, /*relax*/ false, iterations);
///
/// Why it gives the same bits: a Gauss-Seidel solve's result depends only on the order in which
/// each body receives its contacts' updates. Islands share no dynamic body, so solving eight
/// side by side, each lane taking its own island's contacts in its own order, leaves every body
/// with the same sequence of float operations as solving the islands one after another. Each
/// lane does the scalar code's operations in the scalar code's order (products and sums lane by
/// lane, 3-vector dot products summed x + (y + z), std::max and the cone's select written as
/// compares, so a -0 or a NaN comes out as the scalar code's does; -ffp-contract=off), and a
/// body that is not dynamic is never written (island_lanes_kernel.h). Why it pays: one contact
/// update is ~200 instructions, each waiting on the one before through the bodies' velocities
/// (a manifold's contacts share their two bodies); eight islands' updates in the lanes of one
/// register wait no longer than one (ship_refit solves ~6,600 contacts in ~2,000 islands of at
/// most 18, ten passes a substep). A row is eight lanes: one AVX2 register where the CPU has
/// it, else two SSE2 ones (island_lanes_rows.h); the bits are the same.
///
/// A pass runs rows of kLanes contacts that share no dynamic body:
/// - solve(): up to kLanes islands side by side, row r holding contact r of each. Forward passes
///   take rows 0, 1, ...; reversed passes (the alternate ones of symmetric Gauss-Seidel) take
///   rows M-1, M-2, ... where M is the longest island's size, so a shorter island's lane idles
///   through the rows past its end first and then runs its own contacts from its last to its
///   first, as solving it alone would. Islands of similar sizes waste the least.
/// - solveOne(): one larger island (a pile), its contacts regrouped by level: a contact's level
///   is one more than the last level at which either of its dynamic bodies was updated, in the
///   pass's order, so contacts of one level share no dynamic body, and running the levels in
///   order gives every body its updates in the pass's order; running the rows last to first
///   gives every body its updates in reverse, as a reversed pass does.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "world/island_lanes_rows.h"
#include "world/solver_contact.h"

namespace bw {

class IslandLanes {
 public:
  static constexpr uint32_t kLanes = lanes::kWidth;
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
  /// solve() of one island whose contacts are regrouped by level (see above), when that fills
  /// the lanes well enough to pay (kMinContactsPerRow); otherwise returns false having changed
  /// nothing (solve it alone).
  bool solveOne(std::span<const uint32_t> island, std::span<SolverContact> contacts, std::span<SolverContactExtras> extras,
                std::span<SolverBody> bodies, bool warmStart, bool relax, int iterations);
  /// Lanes are used where rows hold at least this many contacts on average (an island
  /// regrouped, or islands side by side): a row costs more than one contact's update alone.
  /// monument's island stage, one thread, six runs: 56-74 us a frame at 1.5 contacts a row,
  /// 50-64 at 3, 60-79 at 1; city_rain and ship_refit the same at 1.5 and 3.
  static constexpr uint32_t kMinContactsPerRow = 3;

  /// Rows of kLanes contacts that share no dynamic body, field by field (lane l of a row is one
  /// contact): what a pass reads and updates. An idle lane holds zeros and a static body, so its
  /// arithmetic stays finite and writes nothing. Used by solve(), solveOne() and a coloured
  /// island's colours (any kLanes contacts of one colour make a row).
  class Rows {
   public:
    /// Room for `count` rows (their contents undefined until filled).
    void reserve(uint32_t count);
    /// Row r from contacts[slots[l]] (kNone: an idle lane), lanes 0..kLanes-1, its bodies at
    /// a[l] and b[l] of the body records a pass is given, or the contacts' own a and b when null.
    void fill(uint32_t r, const uint32_t* slots, const uint32_t* a, const uint32_t* b, std::span<const SolverContact> contacts,
              std::span<const SolverContactExtras> extras, bool relax);
    /// The impulses of row r's lanes back to their contacts.
    void writeBack(uint32_t r, const uint32_t* slots, std::span<SolverContact> contacts, std::span<SolverContactExtras> extras) const;
    /// warmStartContact on rows [first, last), in order.
    void warmStart(uint32_t first, uint32_t last, SolverBody* bodies) const;
    /// updateContact (and resistRolling where a lane's contact rolls) on rows [first, last),
    /// forward or from last - 1 down.
    void pass(uint32_t first, uint32_t last, bool reversed, SolverBody* bodies);

   private:
    using Row = lanes::Row;
    using RollRow = lanes::RollRow;
    std::unique_ptr<Row[]> rows_;
    std::unique_ptr<RollRow[]> roll_;
    uint32_t capacity_ = 0;
  };
  static constexpr uint32_t kNone = 0xFFFFFFFFu;  ///< an idle lane's slot
  static constexpr uint32_t kIdleBody = lanes::kIdleBody;

 private:
  // The rows of `order`'s contacts by level into slots_ (kLanes slots a row). Returns the row count.
  uint32_t levelRows(std::span<const uint32_t> order, std::span<const SolverContact> contacts, std::span<const SolverBody> bodies);
  // Rows laid out from slots (kLanes a row) into rows.
  static void fillAll(Rows& rows, std::span<const uint32_t> slots, std::span<const SolverContact> contacts,
                      std::span<const SolverContactExtras> extras, bool relax);
  static void writeBackAll(const Rows& rows, std::span<const uint32_t> slots, std::span<SolverContact> contacts,
                           std::span<SolverContactExtras> extras);
  // The rows of slots_ solved from laying out to writing back (what solve and solveOne share).
  void runRows(uint32_t rows, std::span<SolverContact> contacts, std::span<SolverContactExtras> extras,
               std::span<SolverBody> bodies, bool warmStart, bool relax, int iterations);

  Rows rows_;
  std::vector<uint32_t> slots_;  // the rows' contacts, kLanes a row (kNone: an idle lane)
  std::vector<uint32_t> bodyLevel_, levelOf_, levelStart_;  // levelRows() scratch (bodyLevel_: 0 between calls)
};

}  // namespace bw
