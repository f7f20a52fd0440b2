#pragma once
/// How long one core takes to see a cache line another core just wrote: two threads pass a
/// counter back and forth, and a round trip is two hand-overs.
///
///   bw::CoreHandover h = bw::measureCoreHandover();
///   if (h.measured) std::printf("%.0f ns a hand-over\n", h.medianNs);
///
/// Why a scaling run reports it: stages that pass work between threads every few microseconds
/// (the coloured solve's waves hand their bodies from core to core) slow down with it, and on a
/// VM it is not a property of the machine but of where the host placed the vCPUs at the time.
/// On this project's 2-vCPU host it ranged 25-240 ns from one process to the next, and
/// crate_pile's 2-thread solver took 1.2-1.5 ms a frame in some runs and 2.8-3.2 ms in others
/// of the same binary (profiles/RESULTS.md, session 49): a measured speedup is read beside it.
/// The threads are placed by the OS (not pinned): the figure is for the pair it chose.
#include <cstdint>

namespace bw {

struct CoreHandover {
  bool measured = false;        ///< false: fewer than 2 hardware threads, never on two CPUs, or kMaxStalledBatches stalled
  double medianNs = 0;          ///< median over the finished batches of one hand-over (half a round trip)
  double minNs = 0;             ///< the fastest batch's
  uint32_t batches = 0;         ///< batches that finished within their limit
  uint32_t stalledBatches = 0;  ///< batches given up (one thread stopped for longer than the limit)
};

/// A measurement stops, unmeasured, at this many stalled batches.
inline constexpr uint32_t kMaxStalledBatches = 3;
/// How long the two threads may take to be on different CPUs before anything is timed (the OS
/// starts a new thread on its creator's core and moves it later); past it: unmeasured.
inline constexpr uint32_t kWarmUpMs = 300;

/// Times `batches` batches of `roundTrips` round trips between the calling thread and one it
/// starts, once the two run on different CPUs (sched_getcpu). A batch that runs over
/// `batchLimitMs` (checked every 64 round trips and inside long waits) is given up and not
/// counted: a thread stopped or moved on the way (a VM's vCPU held by its host); two threads that
/// end up sharing a core wait a time slice for each hand-over (they yield now and then, so they
/// progress). kMaxStalledBatches end the measurement unmeasured, so it costs at most about
/// kWarmUpMs + (batches + kMaxStalledBatches) * batchLimitMs. Throws InvalidInput for batches
/// or roundTrips of 0.
CoreHandover measureCoreHandover(uint32_t batches = 9, uint32_t roundTrips = 2000, double batchLimitMs = 20.0);

}  // namespace bw
