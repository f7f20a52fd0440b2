#include "cli/progress_watch.h"

#include <cstdio>

namespace bw::cli {

ProgressWatch::ProgressWatch(bool enabled) {
  if (enabled) thread_ = std::thread([this] { watch(); });
}

ProgressWatch::~ProgressWatch() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void ProgressWatch::begin(const char* what, uint32_t index, uint32_t frames) {
  std::lock_guard lock(mutex_);
  what_ = what;
  index_ = index;
  frames_ = frames;
  started_ = Clock::now();
  ++step_;
}

void ProgressWatch::end() {
  std::lock_guard lock(mutex_);
  what_ = nullptr;
}

uint32_t ProgressWatch::printed() const {
  std::lock_guard lock(mutex_);
  return printed_;
}

void ProgressWatch::watch() {
  std::unique_lock lock(mutex_);
  uint64_t step = 0;
  Clock::time_point next;
  while (!stop_) {
    if (what_ && step != step_) {  // a new step: first report one second after it began
      step = step_;
      next = started_ + std::chrono::seconds(1);
    }
    if (!what_) {
      wake_.wait_for(lock, std::chrono::milliseconds(200));
      continue;
    }
    if (wake_.wait_until(lock, next, [&] { return stop_ || !what_ || step != step_; })) continue;
    const double s = std::chrono::duration<double>(Clock::now() - started_).count();
    if (frames_ > 0) std::fprintf(stderr, "  ... still running %s %u/%u: %.0f s\n", what_, index_, frames_, s);
    else std::fprintf(stderr, "  ... still %s: %.0f s\n", what_, s);
    ++printed_;
    next += std::chrono::seconds(1);
  }
}

}  // namespace bw::cli
