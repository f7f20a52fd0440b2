#pragma once
/// Explicit thread-count control over oneTBB and deterministic parallel helpers.
///
///   bw::JobSystem jobs(4);                       // 4 worker threads (1 = serial)
///   jobs.parallelFor(0, n, 256, [&](uint32_t begin, uint32_t end) { ... });
///
/// Determinism contract: parallelFor splits [begin, end) into chunks that depend only on the
/// range and the grain (never on the thread count or on timing), so a stage that writes one
/// output slot per item, or one partial result per chunk merged in chunk order, gives
/// bit-identical results for any thread count.
/// Backend: oneTBB (task_arena + parallel_for); in ThreadSanitizer builds a std::thread pool
/// with the same chunking, because TSan cannot see inside Debian's uninstrumented oneTBB.
/// Thread safety: a JobSystem may be used from one controlling thread at a time. It sets
/// oneTBB's process-wide parallelism limit while it lives, so keep one JobSystem per process
/// (or nest only equal thread counts): TBB applies the smallest limit of all live ones.
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

namespace bw {

class JobSystem {
 public:
  /// threads >= 1; throws InvalidInput otherwise. More threads than cores is allowed.
  explicit JobSystem(int threads);
  ~JobSystem();
  JobSystem(const JobSystem&) = delete;
  JobSystem& operator=(const JobSystem&) = delete;

  int threadCount() const { return threads_; }

  /// Runs body(chunkBegin, chunkEnd) over [begin, end) in chunks of at most `grain` items,
  /// chunk boundaries at begin + k * grain. Returns when all chunks are done.
  void parallelFor(uint32_t begin, uint32_t end, uint32_t grain,
                   const std::function<void(uint32_t, uint32_t)>& body);

  /// Number of chunks parallelFor uses for a range: callers size per-chunk outputs with it.
  static uint32_t chunkCount(uint32_t begin, uint32_t end, uint32_t grain) {
    return end > begin ? (end - begin + grain - 1) / grain : 0;
  }

  /// Runs `waves` waves in order, wave w as chunksOf[w] chunks in parallel (body(w, chunk)),
  /// each wave starting once every chunk of the one before has finished: what parallelFor
  /// once per wave would do, but in one parallel region whose threads pass from wave to wave
  /// through atomic counters (a coloured island's 8 iterations of 20-60 colours were as many
  /// fork-joins). A thread that finds a wave's chunks all taken waits for the wave to finish
  /// (spinning, then yielding); the thread that took a chunk is running it, so the waves finish
  /// even when fewer threads than asked ever arrive. body must not call this JobSystem.
  void parallelWaves(const std::vector<uint32_t>& chunksOf, const std::function<void(uint32_t, uint32_t)>& body);

  /// Runs f inside this system's arena (so nested TBB algorithms use its thread count).
  void run(const std::function<void()>& f);

  /// Starts f beside what the controlling thread does next: a worker takes it while the caller
  /// goes on (work that needs no one to wait for it, kept off the frame's critical path: the
  /// render thread's wake). joinBeside() returns once every f started so far has finished, and
  /// rethrows the first exception one threw. With one thread f runs at once, on the caller (its
  /// exception still waits for joinBeside); the TSan build's pool runs them on a thread of
  /// their own. f must not call this JobSystem. The destructor joins (dropping an exception).
  void runBeside(std::function<void()> f);
  void joinBeside();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int threads_;
  std::exception_ptr besideError_;  // the first beside job's exception, for joinBeside
  std::mutex besideErrorLock_;                    // held by a beside job storing it
};

}  // namespace bw
