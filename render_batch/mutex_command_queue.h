#pragma once
/// Mutex-guarded command queue: every push takes one lock, as the render-command queue of the
/// engine in article 000 did. The consumer swaps the whole pending vector out under the lock,
/// so it holds the lock for O(1), and the two vectors trade buffers (no allocation once warm).
#include <mutex>
#include <vector>

#include "render_batch/command_queue.h"

namespace bw {

/// std::mutex + vector queue (see file comment).
class MutexCommandQueue final : public CommandQueue {
 public:
  /// Reserves room for expectedPerFrame commands in the pending buffer.
  explicit MutexCommandQueue(size_t expectedPerFrame = 0) { pending_.reserve(expectedPerFrame); }
  /// Takes the lock and appends (one lock per command: the cost being measured).
  void push(const RenderCommand& command) override;
  /// Swaps the pending buffer out under the lock.
  void popAll(std::vector<RenderCommand>& out) override;
  /// "mutex".
  const char* name() const override { return "mutex"; }

 private:
  std::mutex mutex_;
  std::vector<RenderCommand> pending_;  // guarded by mutex_
};

}  // namespace bw
