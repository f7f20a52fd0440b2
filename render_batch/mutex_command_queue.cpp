#include "render_batch/mutex_command_queue.h"

namespace bw {

void MutexCommandQueue::push(const RenderCommand& command) {
  std::lock_guard<std::mutex> lock(mutex_);
  pending_.push_back(command);
}

void MutexCommandQueue::popAll(std::vector<RenderCommand>& out) {
  if (out.empty()) {
    // note: swapping hands the consumer the filled buffer and gives producers the consumer's
    // empty one with its capacity, so steady-state frames never reallocate.
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.swap(out);
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  out.insert(out.end(), pending_.begin(), pending_.end());
  pending_.clear();
}

}  // namespace bw
