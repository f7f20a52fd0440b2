#pragma once
/// How transform updates reach the render thread.
#include <cstdint>
#include <optional>
#include <string_view>

namespace bw {

/// Submission strategy compared by the batching benchmarks and tests.
enum class SubmissionMode : uint8_t {
  PerObjectMutex,       ///< one command per update into a mutex-guarded queue (the engine's way)
  PerObjectConcurrent,  ///< one command per update into a lock-free oneTBB queue
  Batched,              ///< one fetch_add per update into an append batch, one command per frame
};

/// All modes, in table order.
inline constexpr SubmissionMode kAllSubmissionModes[] = {SubmissionMode::PerObjectMutex,
                                                          SubmissionMode::PerObjectConcurrent, SubmissionMode::Batched};

/// Stable name used in tables, CSV and benchmark names.
inline const char* submissionModeName(SubmissionMode mode) {
  switch (mode) {
    case SubmissionMode::PerObjectMutex: return "PerObjectMutex";
    case SubmissionMode::PerObjectConcurrent: return "PerObjectConcurrent";
    case SubmissionMode::Batched: return "Batched";
  }
  return "unknown";
}

/// Inverse of submissionModeName.
inline std::optional<SubmissionMode> parseSubmissionMode(std::string_view name) {
  for (SubmissionMode m : kAllSubmissionModes)
    if (name == submissionModeName(m)) return m;
  return std::nullopt;
}

}  // namespace bw
