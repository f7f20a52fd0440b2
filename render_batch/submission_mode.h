#pragma once
/// How transform updates reach the render thread.
#include <cstdint>
#include <optional>
#include <string_view>

namespace bw {

/// Submission strategy compared by the batching benchmarks and tests.
/// The per-object modes come twice: as the article's engine sent them (a light move also sends a
/// light-radius refresh, which batched submission does not) and without that refresh
/// (`NoRadius`), the like-for-like rival of Batched: the same updates, one command each.
enum class SubmissionMode : uint8_t {
  PerObjectMutex,               ///< one command per update into a mutex-guarded queue, + radius refresh per light (the engine's way)
  PerObjectConcurrent,          ///< one command per update into a lock-free oneTBB queue, + radius refresh per light
  Batched,                      ///< one fetch_add per update into an append batch, one command per frame
  PerObjectMutexNoRadius,       ///< PerObjectMutex without the radius refresh (like for like with Batched)
  PerObjectConcurrentNoRadius,  ///< PerObjectConcurrent without the radius refresh (like for like with Batched)
};

/// All modes, in table order.
inline constexpr SubmissionMode kAllSubmissionModes[] = {
    SubmissionMode::PerObjectMutex,      SubmissionMode::PerObjectMutexNoRadius, SubmissionMode::PerObjectConcurrent,
    SubmissionMode::PerObjectConcurrentNoRadius, SubmissionMode::Batched};

/// Stable name used in tables, CSV and benchmark names.
inline const char* submissionModeName(SubmissionMode mode) {
  switch (mode) {
    case SubmissionMode::PerObjectMutex: return "PerObjectMutex";
    case SubmissionMode::PerObjectConcurrent: return "PerObjectConcurrent";
    case SubmissionMode::Batched: return "Batched";
    case SubmissionMode::PerObjectMutexNoRadius: return "PerObjectMutexNoRadius";
    case SubmissionMode::PerObjectConcurrentNoRadius: return "PerObjectConcurrentNoRadius";
  }
  return "unknown";
}

/// True for the modes that enqueue a light-radius refresh per light move (the engine's way).
inline bool sendsLightRadius(SubmissionMode mode) {
  return mode == SubmissionMode::PerObjectMutex || mode == SubmissionMode::PerObjectConcurrent;
}

/// True for the modes that enqueue into the lock-free queue.
inline bool usesConcurrentQueue(SubmissionMode mode) {
  return mode == SubmissionMode::PerObjectConcurrent || mode == SubmissionMode::PerObjectConcurrentNoRadius;
}

/// Inverse of submissionModeName.
inline std::optional<SubmissionMode> parseSubmissionMode(std::string_view name) {
  for (SubmissionMode m : kAllSubmissionModes)
    if (name == submissionModeName(m)) return m;
  return std::nullopt;
}

}  // namespace bw
