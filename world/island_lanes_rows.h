#pragma once
/// The rows IslandLanes solves (island_lanes.h), and the kernels that run them: SSE2 on every
/// x86-64 (a row as two halves of four lanes), AVX2 where the CPU has it (a row in one register
/// of eight lanes), chosen at run time. Both do the scalar reference's float operations lane by
/// lane in its order, so they give the same bits (tested against each other and the reference).
#include <cstdint>

namespace bw::lanes {

inline constexpr uint32_t kWidth = 8;             ///< lanes of a row
inline constexpr uint32_t kIdleBody = 0xFFFFFFFFu;  ///< an idle lane's body index

/// Eight contacts that share no dynamic body, field by field (lane l is one contact). An idle
/// lane holds zeros and a static, still body, so its arithmetic stays finite and writes nothing.
struct alignas(32) Row {
  float n[3][kWidth], bias[kWidth], friction[kWidth];
  float rA[3][kWidth], rB[3][kWidth], t1[3][kWidth], t2[3][kWidth];
  float angA[3][3][kWidth], angB[3][3][kWidth];  // [direction: n, t1, t2][axis][lane]
  float mass[3][kWidth], lambda[3][kWidth];      // [direction][lane]
  uint32_t a[kWidth], b[kWidth];                 // body indices; kIdleBody in an idle lane
  uint32_t active;                               // lanes holding a contact, one bit each
  uint32_t rolls;                                // lanes whose contact rolls (rolling > 0), one bit each
};
/// The rolling resistance of a row's contacts (written only for rows where a lane rolls).
struct alignas(32) RollRow {
  float rolling[kWidth], lambdaR[2][kWidth], massR[2][kWidth];
  float rollA[2][3][kWidth], rollB[2][3][kWidth];  // [tangent][axis][lane]
};

// The kernels take the SolverBody records as floats, eight a body: v (3), invMass, w (3), the
// dynamic word (island_lanes.cpp checks the layout). note: the AVX2 kernels' file is compiled
// with -mavx2, so it includes nothing with inline code shared with other files (Eigen above
// all): the linker could keep its AVX2 copy of such a function for every caller.

/// warmStartContact on rows [first, last), in order.
void warmStartSse2(const Row* rows, uint32_t first, uint32_t last, float* bodies);
/// updateContact, then resistRolling where a lane's contact rolls, on rows [first, last),
/// forward or from last - 1 down.
void passSse2(Row* rows, RollRow* roll, uint32_t first, uint32_t last, bool reversed, float* bodies);
/// The same with AVX2; call only when avx2() is true.
void warmStartAvx2(const Row* rows, uint32_t first, uint32_t last, float* bodies);
void passAvx2(Row* rows, RollRow* roll, uint32_t first, uint32_t last, bool reversed, float* bodies);

/// Whether the AVX2 kernels run: the CPU has AVX2 (this build compiled them), unless a test
/// asked for the SSE2 ones.
bool avx2();
/// For tests: run the SSE2 kernels even where AVX2 is there (false restores the choice).
void preferSse2ForTests(bool on);

}  // namespace bw::lanes
