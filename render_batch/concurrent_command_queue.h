#pragma once
/// Lock-free command queue on oneTBB's concurrent_queue: the "fix" of putting a better queue
/// under per-object submission. It removes the lock but still does one queue operation (a
/// page allocation and a 192-byte command copy) per moved object, which batching removes.
#include <memory>
#include <oneapi/tbb/concurrent_queue.h>

#include "render_batch/command_queue.h"

namespace bw {

/// tbb::concurrent_queue-backed queue (see file comment).
class ConcurrentCommandQueue final : public CommandQueue {
 public:
  /// Lock-free push (allocates one queue page per command).
  void push(const RenderCommand& command) override { queue_.push(command); }
  /// Pops until the queue is empty.
  void popAll(std::vector<RenderCommand>& out) override;
  /// "concurrent".
  const char* name() const override { return "concurrent"; }

 private:
  // note: pages come from std::allocator rather than oneTBB's cache_aligned_allocator: the
  // Debian libtbb is not ThreadSanitizer-instrumented, and memory it recycles shows up as
  // false races; with malloc-backed pages TSan sees every allocation and the queue is
  // checked like the rest of the code. oneTBB gives items over 128 bytes one page each, so
  // every push allocates; glibc malloc measured no slower than cache_aligned_allocate here.
  tbb::concurrent_queue<RenderCommand, std::allocator<RenderCommand>> queue_;
};

}  // namespace bw
