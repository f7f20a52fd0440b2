#include "jobs/job_system.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>
#include <oneapi/tbb/task_group.h>
#include <string>
#include <thread>
#include <vector>

#include "collision/core/argument_checks.h"

namespace bw {

#if defined(__SANITIZE_THREAD__)
// note: Debian's oneTBB is not built with ThreadSanitizer, so TSan cannot see the
// synchronisation inside its task scheduler and reports races in TBB's own range splitting.
// Under TSan the same fixed-chunk parallelFor runs on a small std::thread pool whose
// synchronisation TSan understands, so races in *our* job bodies stay visible.
#define BW_JOBS_STD_THREAD_POOL 1
#endif

#if BW_JOBS_STD_THREAD_POOL

struct JobSystem::Impl {
  explicit Impl(int threads) {
    for (int i = 1; i < threads; ++i) workers.emplace_back([this] { workerLoop(); });
  }
  ~Impl() {
    {
      std::lock_guard<std::mutex> lock(m);
      stop = true;
    }
    wake.notify_all();
    for (auto& w : workers) w.join();
    {
      std::lock_guard<std::mutex> lock(besideLock);
      besideStop = true;
    }
    besideWake.notify_all();
    if (besideThread.joinable()) besideThread.join();
  }
  void workerLoop() {
    uint64_t seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(m);
        wake.wait(lock, [&] { return stop || generation != seen; });
        if (stop) return;
        seen = generation;
      }
      runChunks();
    }
  }
  void runChunks() {
    for (uint32_t c; (c = next.fetch_add(1)) < count;) (*task)(c);
    std::lock_guard<std::mutex> lock(m);
    if (++finished == workers.size() + 1) done.notify_all();
  }
  void run(const std::function<void()>& f) { f(); }
  // note: beside jobs run on a thread of their own, so TSan sees them run concurrently with
  // the caller's work (one thread for all: a world hands one over every frame).
  void beside(std::function<void()> f) {
    {
      std::lock_guard<std::mutex> lock(besideLock);
      besideQueue.push_back(std::move(f));
      ++besidePending;
      if (!besideThread.joinable()) besideThread = std::thread([this] { besideLoop(); });
    }
    besideWake.notify_all();
  }
  void besideLoop() {
    std::unique_lock<std::mutex> lock(besideLock);
    for (;;) {
      besideWake.wait(lock, [&] { return besideStop || !besideQueue.empty(); });
      if (besideQueue.empty()) return;  // stopping, nothing left
      std::function<void()> f = std::move(besideQueue.front());
      besideQueue.pop_front();
      lock.unlock();
      f();  // JobSystem::runBeside's wrapper catches
      lock.lock();
      --besidePending;
      besideWake.notify_all();
    }
  }
  void joinBeside() {
    std::unique_lock<std::mutex> lock(besideLock);
    besideWake.wait(lock, [&] { return besidePending == 0; });
  }
  void parallel(uint32_t chunks, const std::function<void(uint32_t)>& body) {
    {
      std::lock_guard<std::mutex> lock(m);
      task = &body;
      count = chunks;
      next = 0;
      finished = 0;
      ++generation;
    }
    wake.notify_all();
    runChunks();
    std::unique_lock<std::mutex> lock(m);
    done.wait(lock, [&] { return finished == workers.size() + 1; });
  }

  std::vector<std::thread> workers;
  std::mutex m;
  // beside jobs
  std::thread besideThread;
  std::mutex besideLock;
  std::condition_variable besideWake;
  std::deque<std::function<void()>> besideQueue;
  size_t besidePending = 0;
  bool besideStop = false;
  std::condition_variable wake, done;
  uint64_t generation = 0;
  bool stop = false;
  const std::function<void(uint32_t)>* task = nullptr;
  std::atomic<uint32_t> next{0};
  uint32_t count = 0;
  size_t finished = 0;
};

#else

struct JobSystem::Impl {
  // note: global_control lifts TBB's default cap (the core count) so a 16-thread run on a
  // 2-core machine really has 16 threads, which the determinism tests rely on.
  explicit Impl(int threads)
      : control(tbb::global_control::max_allowed_parallelism, size_t(threads)), arena(threads) {}
  tbb::global_control control;
  tbb::task_arena arena;
  tbb::task_group besides;
  void run(const std::function<void()>& f) { arena.execute(f); }
  // note: spawned inside the arena, so one of its workers steals it while the caller, back
  // outside, goes on; waited for inside it (oneTBB's pattern for a task_group and an arena).
  // f never throws (JobSystem::runBeside's wrapper catches), so none cancels the others.
  void beside(std::function<void()> f) {
    arena.execute([&] { besides.run(std::move(f)); });
  }
  void joinBeside() {
    arena.execute([&] { besides.wait(); });
  }
  void parallel(uint32_t chunks, const std::function<void(uint32_t)>& body) {
    // note: iterate over chunk numbers, not items, so chunk boundaries are fixed whatever the
    // partitioner does; the partitioner only decides which thread runs which chunks.
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<uint32_t>(0, chunks, 1),
                        [&](const tbb::blocked_range<uint32_t>& r) {
                          for (uint32_t c = r.begin(); c != r.end(); ++c) body(c);
                        },
                        tbb::simple_partitioner());
    });
  }
};

#endif

JobSystem::JobSystem(int threads) : threads_(threads) {
  if (threads < 1 || threads > 1024)
    throw InvalidInput("JobSystem: thread count is " + std::to_string(threads) + ", expected 1..1024");
  impl_ = std::make_unique<Impl>(threads);
}

JobSystem::~JobSystem() {
  // note: a beside job still running would outlive what it reads; its exception is dropped here
  // (a destructor must not throw).
  try {
    joinBeside();
  } catch (...) {
  }
}

void JobSystem::parallelFor(uint32_t begin, uint32_t end, uint32_t grain,
                            const std::function<void(uint32_t, uint32_t)>& body) {
  if (end <= begin) return;
  if (grain == 0) grain = 1;
  const uint32_t chunks = chunkCount(begin, end, grain);
  auto chunk = [&](uint32_t c) { body(begin + c * grain, std::min(end, begin + (c + 1) * grain)); };
  if (threads_ == 1 || chunks == 1) {
    for (uint32_t c = 0; c < chunks; ++c) chunk(c);
    return;
  }
  impl_->parallel(chunks, chunk);
}

namespace {
// Waiting for another thread's chunk: a short spin (the chunk is microseconds), then yields so
// that a run with more threads than cores lets the running thread finish it.
void backOff(uint32_t spins) {
  if (spins < 64) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  } else {
    std::this_thread::yield();
  }
}

// One wave's finish counter, on a cache line of its own (every chunk's thread adds to it).
struct alignas(64) WaveCounter {
  std::atomic<uint32_t> finished{0};
};
}  // namespace

void JobSystem::parallelWaves(const std::vector<uint32_t>& chunksOf, const std::function<void(uint32_t, uint32_t)>& body) {
  const uint32_t waves = uint32_t(chunksOf.size());
  if (threads_ == 1) {
    for (uint32_t w = 0; w < waves; ++w)
      for (uint32_t c = 0; c < chunksOf[w]; ++c) body(w, c);
    return;
  }
  // Member m owns the m-th contiguous slice of every wave's chunks and runs it first, then
  // takes what is left of the other slices. A wave's chunks are in the island's order, so the
  // same slice of successive waves touches mostly the same contacts and bodies: they stay in one
  // core's cache instead of moving between cores every wave (dynamic taking, as before, made the
  // coloured solve's work 24-34% larger on two threads than on one, this 8-26%: crate_pile,
  // profiles/RESULTS.md session 20).
  // claims[m * waves + w] counts the chunks taken from member m's slice of wave w; one member's
  // counters lie together, so the owner's claims share its lines and a thief touches one line.
  const uint32_t members = uint32_t(threads_);
  std::unique_ptr<WaveCounter[]> finished(new WaveCounter[waves]);
  std::unique_ptr<std::atomic<uint32_t>[]> claims(new std::atomic<uint32_t>[size_t(members) * waves]);
  for (size_t i = 0; i < size_t(members) * waves; ++i) claims[i].store(0, std::memory_order_relaxed);
  std::atomic<uint32_t> completed{0};  // waves [0, completed) are finished
  const auto sliceBegin = [&](uint32_t w, uint32_t m) { return uint32_t(uint64_t(chunksOf[w]) * m / members); };
  const auto member = [&](uint32_t m) {
    for (uint32_t w = 0; w < waves; ++w) {
      for (uint32_t spins = 0; completed.load(std::memory_order_acquire) < w; ++spins) backOff(spins);
      if (chunksOf[w] == 0) {  // nothing to run: the first thread here finishes it
        uint32_t expected = w;
        completed.compare_exchange_strong(expected, w + 1, std::memory_order_acq_rel);
        continue;
      }
      for (uint32_t k = 0; k < members; ++k) {
        const uint32_t owner = (m + k) % members;
        const uint32_t begin = sliceBegin(w, owner), size = sliceBegin(w, owner + 1) - begin;
        std::atomic<uint32_t>& claim = claims[size_t(owner) * waves + w];
        // note: a slice that is empty or taken costs a read, not a write to its owner's line
        // (with 16 threads on a wave of 4 chunks most slices are empty).
        if (size == 0 || claim.load(std::memory_order_relaxed) >= size) continue;
        for (;;) {
          const uint32_t i = claim.fetch_add(1, std::memory_order_relaxed);
          if (i >= size) break;
          body(w, begin + i);
          // The last chunk's thread opens the next wave; its release (after every finisher's,
          // through the counter) makes the wave's writes visible to whoever runs the next one.
          if (finished[w].finished.fetch_add(1, std::memory_order_acq_rel) + 1 == chunksOf[w])
            completed.store(w + 1, std::memory_order_release);
        }
      }
    }
  };
  impl_->parallel(uint32_t(threads_), member);
}

void JobSystem::run(const std::function<void()>& f) { impl_->run(f); }

void JobSystem::runBeside(std::function<void()> f) {
  // One wrapper for every backend: the first exception is kept for joinBeside.
  auto job = [this, f = std::move(f)] {
    try {
      f();
    } catch (...) {
      std::lock_guard<std::mutex> lock(besideErrorLock_);
      if (!besideError_) besideError_ = std::current_exception();
    }
  };
  if (threads_ > 1) {
    impl_->beside(std::move(job));
  } else {
    job();
  }
}

void JobSystem::joinBeside() {
  if (threads_ > 1) impl_->joinBeside();
  std::exception_ptr error;
  std::swap(error, besideError_);
  if (error) std::rethrow_exception(error);
}

}  // namespace bw
