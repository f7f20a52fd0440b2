#pragma once
/// BW_ASSERT(cond): a cheap internal invariant, checked in the debug, asan and tsan builds
/// (CMake defines BW_ENABLE_ASSERTS there) and compiled out of release, where the figures
/// are measured. Caller mistakes are not asserts: they throw InvalidInput (core/errors.h).
#include <cstdio>
#include <cstdlib>

namespace bw {

/// Prints the failed condition and where it is, then aborts (a debugger or sanitizer stops there).
[[noreturn]] inline void assertFailed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: BW_ASSERT(%s) failed\n", file, line, condition);
  std::abort();
}

}  // namespace bw

#if defined(BW_ENABLE_ASSERTS)
#define BW_ASSERT(cond) ((cond) ? void(0) : ::bw::assertFailed(#cond, __FILE__, __LINE__))
#else
#define BW_ASSERT(cond) ((void)0)
#endif
