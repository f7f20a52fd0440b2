#include "jobs/core_handover.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <sched.h>
#include <string>
#include <thread>
#include <vector>

#include "collision/core/argument_checks.h"

namespace bw {
namespace {

using Clock = std::chrono::steady_clock;

// Each value on a line of its own: the flags are read by the spinning partner (and stay in its
// cache), and a write to the ball's line is the one thing being timed.
struct alignas(64) Line {
  std::atomic<uint64_t> value{0};
};

inline void relax(uint32_t spins) {
  // After a long wait the other thread is likely not running (more threads than cores): let it.
  if (spins % 4096 == 4095) {
    std::this_thread::yield();
    return;
  }
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

}  // namespace

CoreHandover measureCoreHandover(uint32_t batches, uint32_t roundTrips, double batchLimitMs) {
  if (batches == 0 || roundTrips == 0)
    throw InvalidInput("measureCoreHandover: batches is " + std::to_string(batches) + " and roundTrips " + std::to_string(roundTrips) +
                       "; both must be at least 1");
  CoreHandover result;
  if (std::thread::hardware_concurrency() < 2) return result;
  Line ball, stop, partnerCpu, warming;
  warming.value.store(1, std::memory_order_relaxed);
  // The ball is even when it is this thread's turn and odd when it is the partner's; each side
  // adds one. The partner leaves when stop is set, after its last answer (every hand-over this
  // thread starts, it waits for).
  std::thread partner([&] {
    for (uint64_t expect = 1;; expect += 2) {
      for (uint32_t spins = 0; ball.value.load(std::memory_order_acquire) != expect; ++spins) {
        if (stop.value.load(std::memory_order_relaxed)) return;
        relax(spins);
      }
      // (read from its own line, which stays in this core's cache once the timing starts)
      if (warming.value.load(std::memory_order_relaxed)) partnerCpu.value.store(uint64_t(int64_t(sched_getcpu())), std::memory_order_relaxed);
      ball.value.store(expect + 1, std::memory_order_release);
    }
  });
  uint64_t value = 0;
  // One round trip. With a deadline, a long wait past it says so (true); the answer is still
  // awaited, so the next round trip starts with the ball here.
  const auto roundTrip = [&](const Clock::time_point* deadline) {
    ball.value.store(value + 1, std::memory_order_release);
    value += 2;
    bool late = false;
    for (uint32_t spins = 0; ball.value.load(std::memory_order_acquire) != value; ++spins) {
      if (deadline && !late && spins % 1024 == 1023 && Clock::now() > *deadline) late = true;
      relax(spins);
    }
    return late;
  };
  // A new thread often starts on its creator's core and is moved by the OS only later (the first
  // measurement in a process stalled three batches in a row here): hand over, yielding now and
  // then, until 64 hand-overs in a row found the two on different CPUs, or give up.
  const auto warmUpEnd = Clock::now() + std::chrono::milliseconds(kWarmUpMs);
  for (uint32_t apart = 0; apart < 64;) {
    if (Clock::now() > warmUpEnd) {
      stop.value.store(1, std::memory_order_relaxed);
      partner.join();
      return result;
    }
    roundTrip(nullptr);
    const int cpu = sched_getcpu();  // -1 where the OS cannot say: then the timing is taken as it comes
    const bool differ = cpu < 0 || partnerCpu.value.load(std::memory_order_relaxed) != uint64_t(int64_t(cpu));
    apart = differ ? apart + 1 : 0;
    if (!differ) std::this_thread::yield();
  }
  warming.value.store(0, std::memory_order_relaxed);  // seen by the partner's next answers at the latest
  const auto limit = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(batchLimitMs));
  std::vector<double> ns;
  for (uint32_t b = 0; b < batches && result.stalledBatches < kMaxStalledBatches; ++b) {
    const auto start = Clock::now();
    const auto deadline = start + limit;
    bool over = false;
    for (uint32_t i = 0; i < roundTrips && !over; ++i) {
      over = roundTrip(&deadline);
      if (i % 64 == 63 && Clock::now() > deadline) over = true;
    }
    if (over) ++result.stalledBatches;
    else ns.push_back(std::chrono::duration<double, std::nano>(Clock::now() - start).count() / (2.0 * roundTrips));
  }
  stop.value.store(1, std::memory_order_relaxed);
  partner.join();
  if (result.stalledBatches >= kMaxStalledBatches || ns.empty()) return result;
  std::sort(ns.begin(), ns.end());
  result.measured = true;
  result.batches = uint32_t(ns.size());
  result.medianNs = ns[ns.size() / 2];
  result.minNs = ns.front();
  return result;
}

}  // namespace bw
