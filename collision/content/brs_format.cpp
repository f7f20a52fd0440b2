#include "collision/content/brs_format.h"

#include <cstring>
#include <limits>
#include <zlib.h>

#include "collision/core/argument_checks.h"

namespace bw::brs {

// Latin-1 (positive length, NUL-terminated) or UTF-16 (negative length, low bytes kept).
std::string BrsReader::string(const char* what) {
  const int32_t n = i32(what);
  std::string s;
  if (n >= 0) {
    const uint8_t* p = take(size_t(n), what);
    s.assign(reinterpret_cast<const char*>(p), size_t(n));
  } else {
    if (n == std::numeric_limits<int32_t>::min()) failHere(std::string(what) + " has an invalid length");
    const size_t units = size_t(-int64_t(n));
    if (units > remaining() / 2) failHere(std::string("truncated: ") + what + " needs " + std::to_string(units * 2) + " bytes");
    const uint8_t* p = take(units * 2, what);
    s.resize(units);
    for (size_t i = 0; i < units; ++i) s[i] = char(p[2 * i]);
  }
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

// Reads one section header and returns its uncompressed bytes.
std::vector<uint8_t> readSection(ByteReader& file, const char* name, const std::string& fileName) {
  const std::string where = std::string(name) + " section";
  const int32_t uncompressed = file.i32(where.c_str());
  const int32_t compressed = file.i32(where.c_str());
  if (uncompressed < 0 || compressed < 0 || uncompressed > kMaxSectionBytes)
    failFile(fileName, where,
         "sizes out of range (uncompressed " + std::to_string(uncompressed) + ", compressed " +
             std::to_string(compressed) + ")");
  if (compressed > 0 && compressed >= uncompressed)
    failFile(fileName, where,
         "compressed size " + std::to_string(compressed) + " is not below the uncompressed size " +
             std::to_string(uncompressed));
  const size_t stored = compressed > 0 ? size_t(compressed) : size_t(uncompressed);
  if (stored > file.remaining())
    failFile(fileName, where,
         "truncated: needs " + std::to_string(stored) + " bytes at offset " + std::to_string(file.position()) +
             ", only " + std::to_string(file.remaining()) + " left");
  const uint8_t* p = file.take(stored, where.c_str());
  std::vector<uint8_t> out(static_cast<size_t>(uncompressed), uint8_t(0));
  if (compressed == 0) {
    if (!out.empty()) std::memcpy(out.data(), p, out.size());
    return out;
  }
  uLongf produced = uLongf(out.size());
  const int rc = uncompress(out.data(), &produced, p, uLong(compressed));
  if (rc != Z_OK || produced != out.size())
    failFile(fileName, where,
         std::string("zlib data is corrupt (") + (rc == Z_OK ? "size mismatch" : zError(rc)) + ", expected " +
             std::to_string(uncompressed) + " bytes)");
  return out;
}

Header1 readHeader1(const std::vector<uint8_t>& bytes, const std::string& file) {
  BrsReader r(bytes.data(), bytes.size(), file, "header1");
  Header1 h;
  h.map = r.string("map name");
  h.author = r.string("author name");
  h.description = r.string("description");
  r.take(16, "author id");
  r.string("host name");
  r.take(16, "host id");
  r.take(8, "save time");
  const int32_t n = r.i32("brick count");
  if (n < 0) r.failHere("brick count is negative (" + std::to_string(n) + ")");
  h.brickCount = uint32_t(n);
  return h;
}

Header2 readHeader2(const std::vector<uint8_t>& bytes, int version, const std::string& file) {
  BrsReader r(bytes.data(), bytes.size(), file, "header2");
  Header2 h;
  const uint32_t mods = r.count("mods count", 4);
  for (uint32_t i = 0; i < mods; ++i) r.string("mod name");
  const uint32_t assets = r.count("brick assets count", 4);
  h.assets.reserve(assets);
  for (uint32_t i = 0; i < assets; ++i) h.assets.push_back(r.string("brick asset name"));
  h.colors = r.count("colors count", 4);
  r.take(size_t(h.colors) * 4, "colors");
  h.materials = r.count("materials count", 4);
  for (uint32_t i = 0; i < h.materials; ++i) r.string("material name");
  h.owners = r.count("brick owners count", 24);
  for (uint32_t i = 0; i < h.owners; ++i) {
    r.take(16, "owner id");
    r.string("owner name");
    r.i32("owner brick count");
  }
  if (version >= 9) {
    h.physicalMaterials = r.count("physical materials count", 4);
    for (uint32_t i = 0; i < h.physicalMaterials; ++i) r.string("physical material name");
  }
  return h;
}

// A .brs string inside a bit stream (see BrsReader::string for the encoding).
std::string BitReader::string(const char* what) {
  const int32_t n = i32();
  if (n == std::numeric_limits<int32_t>::min()) failHere(std::string(what) + " has an invalid length");
  // note: the length is checked against the bits left before anything is allocated.
  const bool utf16 = n < 0;
  const uint64_t units = uint64_t(utf16 ? -int64_t(n) : int64_t(n));
  const uint64_t needed = units * (utf16 ? 16 : 8);
  if (needed > bitsLeft())
    failHere(std::string("truncated: ") + what + " needs " + std::to_string(needed / 8) + " bytes, only " +
             std::to_string(bitsLeft() / 8) + " left");
  std::string s(size_t(units), '\0');
  for (uint64_t i = 0; i < units; ++i) s[size_t(i)] = char(bits(utf16 ? 16 : 8) & 0xFF);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

}  // namespace bw::brs
