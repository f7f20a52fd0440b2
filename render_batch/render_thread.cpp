#include "render_batch/render_thread.h"

#include <chrono>
#include <limits>
#include <type_traits>
#include <vector>

namespace bw {

RenderThread::RenderThread(RenderScene scene, std::unique_ptr<CommandQueue> queue, FenceObserver observer)
    : scene_(std::move(scene)), queue_(std::move(queue)), observer_(std::move(observer)) {
  thread_ = std::thread([this] { loop(); });
}

RenderThread::~RenderThread() {
  queue_->push(StopRenderThread{});
  wake();
  thread_.join();
}

void RenderThread::wake() {
  wake_.value.fetch_add(1, std::memory_order_release);
  wake_.value.notify_one();
}

void RenderThread::endFrame(uint64_t frame, bool wakeNow) {
  queue_->push(FrameEnd{frame});
  if (wakeNow) wake();
}

void RenderThread::commitBatch(const TransformBatch& batch, uint64_t frame, bool wakeNow) {
  queue_->push(BatchCommit{&batch, frame});
  if (wakeNow) wake();
}

void RenderThread::waitForFrame(uint64_t frame) {
  uint64_t done = fence_.value.load(std::memory_order_acquire);
  while (done < frame) {
    fence_.value.wait(done, std::memory_order_acquire);
    done = fence_.value.load(std::memory_order_acquire);
  }
  if (failed_.load(std::memory_order_acquire)) std::rethrow_exception(error_);
}

RenderThreadStats RenderThread::stats() const {
  return {commandsExecuted_.load(std::memory_order_relaxed), busyNanoseconds_.load(std::memory_order_relaxed),
          primitiveUpdates_.load(std::memory_order_relaxed), lightUpdates_.load(std::memory_order_relaxed),
          lightRadiusUpdates_.load(std::memory_order_relaxed)};
}

void RenderThread::publishFence(uint64_t frame) {
  const auto now = std::chrono::steady_clock::now();
  local_.busyNanoseconds +=
      static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(now - segmentStart_).count());
  commandsExecuted_.store(local_.commandsExecuted, std::memory_order_relaxed);
  busyNanoseconds_.store(local_.busyNanoseconds, std::memory_order_relaxed);
  primitiveUpdates_.store(local_.primitiveUpdates, std::memory_order_relaxed);
  lightUpdates_.store(local_.lightUpdates, std::memory_order_relaxed);
  lightRadiusUpdates_.store(local_.lightRadiusUpdates, std::memory_order_relaxed);
  if (observer_) observer_(frame, scene_, local_);
  // note: the observer's time is not render work, so the next busy segment starts after it.
  segmentStart_ = std::chrono::steady_clock::now();
  fence_.value.store(frame, std::memory_order_release);
  fence_.value.notify_all();
}

bool RenderThread::execute(const RenderCommand& command) {
  return std::visit(
      [this](const auto& c) -> bool {
        using C = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<C, PrimitiveUpdate>) {
          scene_.applyPrimitive(c);
          ++local_.primitiveUpdates;
        } else if constexpr (std::is_same_v<C, LightUpdate>) {
          scene_.applyLight(c);
          ++local_.lightUpdates;
        } else if constexpr (std::is_same_v<C, LightRadiusUpdate>) {
          scene_.applyLightRadius(c.lightId);
          ++local_.lightRadiusUpdates;
        } else if constexpr (std::is_same_v<C, BatchCommit>) {
          const TransformBatch& batch = *c.batch;
          const uint32_t primitives = batch.primitives.size();
          const uint32_t lights = batch.lights.size();
          for (uint32_t i = 0; i < primitives; ++i) scene_.applyPrimitive(batch.primitives[i]);
          for (uint32_t i = 0; i < lights; ++i) scene_.applyLight(batch.lights[i]);
          local_.primitiveUpdates += primitives;
          local_.lightUpdates += lights;
          publishFence(c.frame);
        } else if constexpr (std::is_same_v<C, FrameEnd>) {
          publishFence(c.frame);
        } else if constexpr (std::is_same_v<C, GrowScene>) {
          scene_.growPrimitives(c.primitiveCount);
        } else {
          return false;
        }
        return true;
      },
      command);
}

void RenderThread::loop() {
  std::vector<RenderCommand> work;
  for (;;) {
    // note: read the wake counter before draining: a frame closed after this read bumps it,
    // so wait() below returns at once instead of missing that frame.
    const uint64_t seen = wake_.value.load(std::memory_order_acquire);
    segmentStart_ = std::chrono::steady_clock::now();
    work.clear();
    queue_->popAll(work);
    if (work.empty()) {
      wake_.value.wait(seen, std::memory_order_acquire);
      continue;
    }
    try {
      for (const RenderCommand& command : work) {
        ++local_.commandsExecuted;
        if (!execute(command)) return;
      }
    } catch (...) {
      error_ = std::current_exception();
      failed_.store(true, std::memory_order_release);
      // Release every waiter: waitForFrame rethrows the error.
      fence_.value.store(std::numeric_limits<uint64_t>::max(), std::memory_order_release);
      fence_.value.notify_all();
      return;
    }
    local_.busyNanoseconds += static_cast<uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - segmentStart_).count());
  }
}

}  // namespace bw
