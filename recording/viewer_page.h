#pragma once
/// `brickworld view`: one self-contained HTML page replaying a recording (FORMAT.md) with
/// three.js (Debian's libjs-three, inlined: nothing is fetched at view time).
#include <cstdint>
#include <string>

namespace bw {

struct ViewerPageStats {
  uint64_t recordingBytes = 0;  ///< decompressed recording embedded
  uint64_t pageBytes = 0;
  uint32_t frames = 0, bodies = 0, grids = 0;
  uint64_t bricks = 0;          ///< bricks of the grids at the start
  uint32_t boxGrids = 0;        ///< of those grids, the ones recorded as OctoBVH boxes (above --record-bricks)
  bool complete = false;        ///< the recording has its END_ (the run finished)
};

/// The largest recording a page embeds (bytes, decompressed).
inline constexpr uint64_t kMaxPageRecordingBytes = uint64_t(512) << 20;

/// Where three.js is read from unless told otherwise (libjs-three's install directory).
std::string defaultThreeJsDir();

/// Reads and checks `recordingPath`, writes the page to `pagePath`. InvalidInput naming what is
/// wrong: an unreadable or malformed recording, three.js missing from `threeDir` (install
/// libjs-three: setup.sh does), an unwritable page.
ViewerPageStats writeViewerPage(const std::string& recordingPath, const std::string& pagePath, const std::string& threeDir);

}  // namespace bw
