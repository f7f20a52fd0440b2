#pragma once
/// Indices are the project's handles (pool slots, bodies, grids, nodes, attachments): 32-bit,
/// stable while the element lives. One value means "no element" everywhere.
#include <cstdint>

namespace bw {

/// The index that names nothing: a missing child, parent, hit, slot or key.
inline constexpr uint32_t kInvalidIndex = 0xFFFFFFFFu;

}  // namespace bw
