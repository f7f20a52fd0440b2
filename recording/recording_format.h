#pragma once
/// The recording's byte layout (FORMAT.md beside this file): block tags, codes and the
/// little-endian appends and reads the writer and reader share.
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "collision/core/math_types.h"

namespace bw {

inline constexpr char kRecordingMagic[8] = {'B', 'W', 'R', 'E', 'C', 'O', 'R', 'D'};
inline constexpr uint32_t kRecordingVersion = 1;

/// A block tag: its four ASCII bytes read as a little-endian u32.
constexpr uint32_t recordingTag(const char (&s)[5]) {
  return uint32_t(uint8_t(s[0])) | uint32_t(uint8_t(s[1])) << 8 | uint32_t(uint8_t(s[2])) << 16 | uint32_t(uint8_t(s[3])) << 24;
}
inline constexpr uint32_t kTagHead = recordingTag("HEAD"), kTagGrid = recordingTag("GRID"), kTagTerrain = recordingTag("TERR"),
                          kTagBody = recordingTag("BODY"), kTagEdit = recordingTag("EDIT"), kTagSplit = recordingTag("SPLT"),
                          kTagFrame = recordingTag("FRAM"), kTagContacts = recordingTag("CONT"), kTagEnd = recordingTag("END_"),
                          kTagNodes = recordingTag("NODE"), kTagMode = recordingTag("MODE");

enum class RecordedKind : uint8_t { Sphere = 0, Box = 1, Capsule = 2, Grid = 3, Terrain = 4, Hull = 5 };
enum class RecordedState : uint8_t { Awake = 0, Asleep = 1, InsideSolid = 2, PushedOut = 3 };

inline constexpr uint32_t kRecordedBrickBytes = 36;    ///< GRID: id + the 32-byte brick
inline constexpr uint32_t kRecordedBodyBytes = 76;     ///< BODY, per body
inline constexpr uint32_t kRecordedEditBytes = 41;     ///< EDIT, per brick edit
inline constexpr uint32_t kRecordedPoseBytes = 33;     ///< FRAM, per moving body
inline constexpr uint32_t kRecordedContactBytes = 28;  ///< CONT, per contact

/// Appends little-endian values to a block payload (the project builds for little-endian
/// x86-64 and AArch64 only, so values are copied as they are in memory).
struct ByteSink {
  std::vector<uint8_t> bytes;
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const size_t at = bytes.size();
    bytes.resize(at + sizeof(T));
    std::memcpy(bytes.data() + at, &v, sizeof(T));
  }
  void put(const Vec3f& v) { put(v.data(), sizeof(float) * 3); }
  void put(const void* data, size_t n) {
    const size_t at = bytes.size();
    bytes.resize(at + n);
    if (n) std::memcpy(bytes.data() + at, data, n);
  }
};

}  // namespace bw
