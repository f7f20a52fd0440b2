#pragma once
/// The two errors every module throws at its public boundary (DESIGN.md, README "Bad input").
/// Both are thrown before anything is modified: a failed call leaves its target as it was.
#include <stdexcept>

namespace bw {

/// Thrown when a caller passes an invalid value (NaN, infinity, out of range, inverted bounds,
/// an unknown handle). The message names the call, the argument and the value.
class InvalidInput : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Thrown when a fixed-capacity resource (pool reservation, batch array) is full. The message
/// names what is full.
class CapacityExceeded : public std::length_error {
 public:
  using std::length_error::length_error;
};

}  // namespace bw
