#pragma once
// Progress for long steps of a CLI run: while a scene builds or a frame runs, a watcher thread
// prints "still <what>: N s" to stderr once a second after the first second, so a 1M-body
// first frame or a 2.5M-brick build never looks hung. Steps under a second print nothing.
//
//   ProgressWatch watch(/*enabled*/ true);
//   watch.begin("building the scene");  ...  watch.end();
//   watch.begin("frame", f + 1, frames); world.step(); watch.end();
//
// begin/end take a mutex (no allocation): cheap next to a frame. Thread safety: begin/end from
// one controlling thread; the watcher only prints.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace bw::cli {

class ProgressWatch {
 public:
  explicit ProgressWatch(bool enabled);
  ~ProgressWatch();
  ProgressWatch(const ProgressWatch&) = delete;
  ProgressWatch& operator=(const ProgressWatch&) = delete;

  /// `what` must outlive the step (a literal). With frames > 0 it prints "what index/frames".
  void begin(const char* what, uint32_t index = 0, uint32_t frames = 0);
  void end();
  /// Lines printed so far (for tests).
  uint32_t printed() const;

 private:
  void watch();

  using Clock = std::chrono::steady_clock;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  const char* what_ = nullptr;  // null: nothing running
  uint32_t index_ = 0, frames_ = 0;
  Clock::time_point started_;
  uint64_t step_ = 0;  // counts begin() calls, so the watcher knows a step ended and another began
  uint32_t printed_ = 0;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace bw::cli
