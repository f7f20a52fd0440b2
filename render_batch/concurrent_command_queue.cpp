#include "render_batch/concurrent_command_queue.h"

namespace bw {

void ConcurrentCommandQueue::popAll(std::vector<RenderCommand>& out) {
  RenderCommand command;
  while (queue_.try_pop(command)) out.push_back(command);
}

}  // namespace bw
