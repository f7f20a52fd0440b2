#include "recording/viewer_page.h"

#include <fstream>
#include <sstream>

#include "collision/core/errors.h"
#include "recording/recording_reader.h"
#include "recording/viewer_assets.h"

namespace bw {
namespace {

std::string readText(const std::string& path, const std::string& why) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidInput("view: cannot read " + path + " (" + why + ")");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4 + bytes.size() / 57);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = uint32_t(bytes[i]) << 16 | uint32_t(bytes[i + 1]) << 8 | bytes[i + 2];
    for (int k = 3; k >= 0; --k) out.push_back(kAlphabet[(v >> (6 * k)) & 63]);
    if ((i / 3) % 1024 == 1023) out.push_back('\n');  // keeps lines short for editors
  }
  if (i < bytes.size()) {
    const uint32_t v = uint32_t(bytes[i]) << 16 | (i + 1 < bytes.size() ? uint32_t(bytes[i + 1]) << 8 : 0);
    out.push_back(kAlphabet[(v >> 18) & 63]);
    out.push_back(kAlphabet[(v >> 12) & 63]);
    out.push_back(i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=');
    out.push_back('=');
  }
  return out;
}

// Replaces the first `{{KEY}}` at or after `from` in `page` with `value`; returns where the
// value ends (the next mark is looked for after it, so inlined text is never searched).
size_t fill(std::string& page, size_t from, const std::string& key, const std::string& value) {
  const std::string mark = "{{" + key + "}}";
  const size_t at = page.find(mark, from);
  if (at == std::string::npos) throw std::logic_error("viewer.html has no " + mark + " in its order");
  page.replace(at, mark.size(), value);
  return at + value.size();
}

}  // namespace

std::string defaultThreeJsDir() { return BW_THREE_JS_DIR; }

ViewerPageStats writeViewerPage(const std::string& recordingPath, const std::string& pagePath, const std::string& threeDir) {
  const std::vector<uint8_t> bytes = readRecordingBytes(recordingPath);
  // A page carries the recording in base64 and the browser decodes it whole: past a few hundred
  // MB a tab runs out of memory (measured: a 52 MB page of a 1M-brick city loads in seconds).
  if (bytes.size() > kMaxPageRecordingBytes)
    throw InvalidInput("view: " + recordingPath + " holds " + std::to_string(bytes.size() >> 20) + " MiB; a page takes at most " +
                       std::to_string(kMaxPageRecordingBytes >> 20) + " MiB: record fewer frames (--frames) or grids as boxes (--record-bricks)");
  const Recording rec = parseRecording(bytes, recordingPath);
  const std::string why = "three.js from Debian's libjs-three; setup.sh installs it, or give --three-dir";
  const std::string three = readText(threeDir + "/three.min.js", why) + "\n" +
                            readText(threeDir + "/examples/js/controls/OrbitControls.js", why);
  if (three.find("</script") != std::string::npos) throw InvalidInput("view: " + threeDir + ": three.js holds '</script' and cannot be inlined");
  std::string page = viewer::kPageTemplate;
  size_t at = fill(page, 0, "STYLE", viewer::kStyle);
  at = fill(page, at, "THREE", three);
  at = fill(page, at, "DATA", base64(bytes));
  fill(page, at, "SCRIPT", viewer::kScript);
  std::ofstream out(pagePath, std::ios::binary);
  if (!out) throw InvalidInput("view: cannot write " + pagePath);
  out << page;
  out.close();
  if (!out) throw InvalidInput("view: writing " + pagePath + " failed (disk full?)");

  ViewerPageStats st;
  st.recordingBytes = bytes.size();
  st.pageBytes = page.size();
  st.frames = uint32_t(rec.frames.size());
  st.bodies = uint32_t(rec.bodies.size());
  st.grids = uint32_t(rec.grids.size());
  for (const RecordedGrid& g : rec.grids)
    if (g.frame < 0) {
      st.bricks += g.brickCount;
      st.boxGrids += g.bricks.empty() && g.brickCount > 0;
    }
  st.complete = rec.complete;
  return st;
}

}  // namespace bw
