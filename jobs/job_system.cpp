#include "jobs/job_system.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include <string>

#include "collision/input_validation.h"

namespace bw {

struct JobSystem::Impl {
  // note: global_control lifts TBB's default cap (the core count) so a 16-thread run on a
  // 2-core machine really has 16 threads, which the determinism tests rely on.
  explicit Impl(int threads)
      : control(tbb::global_control::max_allowed_parallelism, size_t(threads)), arena(threads) {}
  tbb::global_control control;
  tbb::task_arena arena;
};

JobSystem::JobSystem(int threads) : threads_(threads) {
  if (threads < 1 || threads > 1024)
    throw InvalidInput("JobSystem: thread count is " + std::to_string(threads) + ", expected 1..1024");
  impl_ = std::make_unique<Impl>(threads);
}

JobSystem::~JobSystem() = default;

void JobSystem::parallelFor(uint32_t begin, uint32_t end, uint32_t grain,
                            const std::function<void(uint32_t, uint32_t)>& body) {
  if (end <= begin) return;
  if (grain == 0) grain = 1;
  const uint32_t chunks = chunkCount(begin, end, grain);
  if (threads_ == 1 || chunks == 1) {
    for (uint32_t c = 0; c < chunks; ++c) body(begin + c * grain, std::min(end, begin + (c + 1) * grain));
    return;
  }
  // note: iterate over chunk numbers, not items, so chunk boundaries are fixed whatever the
  // partitioner does; the partitioner only decides which thread runs which chunks.
  impl_->arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, chunks, 1),
                      [&](const tbb::blocked_range<uint32_t>& r) {
                        for (uint32_t c = r.begin(); c != r.end(); ++c)
                          body(begin + c * grain, std::min(end, begin + (c + 1) * grain));
                      },
                      tbb::simple_partitioner());
  });
}

void JobSystem::run(const std::function<void()>& f) {
  impl_->arena.execute(f);
}

}  // namespace bw
