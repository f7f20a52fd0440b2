#pragma once
/// Multi-producer, single-consumer queue of render commands.
///
/// Producers are the game thread and the transform-update workers; the consumer is the
/// render thread. Order: commands pushed by one thread are popped in that thread's push
/// order, and a command pushed after another push completed (happens-before) is popped after it.
#include <vector>

#include "render_batch/render_command.h"

namespace bw {

/// Render command queue interface (two implementations: mutex and concurrent).
class CommandQueue {
 public:
  virtual ~CommandQueue() = default;
  /// Appends a command; safe from any number of threads at once.
  virtual void push(const RenderCommand& command) = 0;
  /// Moves every queued command, in order, to the end of out (consumer thread only).
  virtual void popAll(std::vector<RenderCommand>& out) = 0;
  /// Short name for tables ("mutex", "concurrent").
  virtual const char* name() const = 0;
};

}  // namespace bw
