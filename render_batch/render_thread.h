#pragma once
/// Simulated render thread: owns a RenderScene and executes render commands in submission order.
///
///   RenderThread render(RenderScene(primitives, lightRadii), std::make_unique<MutexCommandQueue>());
///   render.enqueue(update);          // any thread, during frame N
///   render.endFrame(N);              // game thread: closes frame N (or commitBatch(batch, N))
///   render.waitForFrame(N);          // game thread: returns once frame N's commands are applied
///
/// Frame fence: endFrame(N)/commitBatch(.., N) enqueue a command after all of frame N's
/// commands (the game thread calls them after the frame's parallel update joined). When the
/// render thread reaches it, frame N is fully applied: it runs the fence observer, then
/// publishes N with a release store; waitForFrame(N) acquires it. So after waitForFrame(N)
/// the game sees all of frame N, and, if it has enqueued nothing since, nothing of frame N+1.
/// Waking: the render thread drains the queue while there is work and sleeps when it is empty
/// until the game thread closes a frame; producers never signal it per command.
/// Errors: a command that throws on the render thread (bad id) stops the loop; the next
/// waitForFrame rethrows it on the game thread.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <thread>

#include "render_batch/command_queue.h"
#include "render_batch/render_scene.h"

namespace bw {

/// Counters the render thread publishes at every fence.
struct RenderThreadStats {
  uint64_t commandsExecuted = 0;       ///< commands executed since start (fences included)
  uint64_t busyNanoseconds = 0;        ///< time spent executing commands since start
  uint64_t primitiveUpdates = 0;       ///< primitive updates applied (per-object and batched)
  uint64_t lightUpdates = 0;           ///< light transform updates applied
  uint64_t lightRadiusUpdates = 0;     ///< light radius refreshes applied (per-object only)
};

/// The render thread (see file comment).
class RenderThread {
 public:
  /// Called on the render thread at each fence, after the frame is applied and before it is published.
  using FenceObserver = std::function<void(uint64_t frame, const RenderScene& scene, const RenderThreadStats& stats)>;

  /// Starts the thread; it owns scene and consumes queue. observer may be empty.
  RenderThread(RenderScene scene, std::unique_ptr<CommandQueue> queue, FenceObserver observer = {});
  /// Sends a stop command after everything submitted, and joins.
  ~RenderThread();
  RenderThread(const RenderThread&) = delete;
  RenderThread& operator=(const RenderThread&) = delete;

  /// Enqueues one command; safe from any thread.
  void enqueue(const RenderCommand& command) { queue_->push(command); }
  /// Closes frame (game thread, after all of the frame's commands were enqueued).
  /// wakeNow false leaves the wake to a wake() that must follow (the caller's job beside the
  /// next frame: a wake is a futex syscall, 6-22 us on this VM).
  void endFrame(uint64_t frame, bool wakeNow = true);
  /// Hands a whole batch over as one command that applies it and closes frame (game thread).
  void commitBatch(const TransformBatch& batch, uint64_t frame, bool wakeNow = true);
  /// Wakes the render thread for what was enqueued; safe from any thread, and harmless twice.
  void wake();
  /// Blocks until frame's fence was reached; rethrows a render-thread error.
  void waitForFrame(uint64_t frame);
  /// Last frame whose fence was reached.
  uint64_t completedFrame() const { return fence_.value.load(std::memory_order_acquire); }

  /// The render scene. Only valid while the render thread is idle: after waitForFrame(N) for
  /// the last frame N submitted, with nothing enqueued since.
  const RenderScene& scene() const { return scene_; }
  /// Counters as of the last fence (read after waitForFrame).
  RenderThreadStats stats() const;
  /// Queue name ("mutex" or "concurrent").
  const char* queueName() const { return queue_->name(); }

 private:
  void loop();
  bool execute(const RenderCommand& command);  // false on StopRenderThread
  void publishFence(uint64_t frame);

  struct alignas(64) PaddedCounter {
    std::atomic<uint64_t> value{0};
  };

  RenderScene scene_;
  std::unique_ptr<CommandQueue> queue_;
  FenceObserver observer_;
  PaddedCounter wake_;   // bumped by the game thread when it closes a frame
  PaddedCounter fence_;  // last frame applied, written by the render thread
  // Written by the render thread only, read by the game thread after a fence.
  std::atomic<uint64_t> commandsExecuted_{0};
  std::atomic<uint64_t> busyNanoseconds_{0};
  std::atomic<uint64_t> primitiveUpdates_{0};
  std::atomic<uint64_t> lightUpdates_{0};
  std::atomic<uint64_t> lightRadiusUpdates_{0};
  std::atomic<bool> failed_{false};
  // Render-thread-only running totals (published through the atomics above at each fence).
  RenderThreadStats local_;
  std::chrono::steady_clock::time_point segmentStart_{};
  std::exception_ptr error_;  // set before failed_ (release), read after it (acquire)
  std::thread thread_;
};

}  // namespace bw
