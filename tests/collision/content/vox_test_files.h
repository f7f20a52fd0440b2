#pragma once
// Helpers for the .vox reader suites (vox_reader_test.cpp, vox_materials_test.cpp,
// vox_bad_files_test.cpp): the shared data folder, a minimal independent chunk scan of a
// well-formed file, and a test-only writer for hand-built files.
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "collision/content/vox_reader.h"
#include "collision/core/argument_checks.h"
#include "collision/terrain/terrain.h"
#include "collision/terrain/voxel_chunk.h"

namespace bw::test::vox {

namespace fs = std::filesystem;

// The shared data folder is a sibling of the repository: <repo>/../shared/data.
inline fs::path dataPath(const std::string& name) {
  const fs::path repo = fs::path(__FILE__).parent_path().parent_path().parent_path().parent_path();
  const fs::path candidate = repo / ".." / "shared" / "data" / name;
  if (fs::exists(candidate)) return candidate;
  for (fs::path dir = fs::current_path(); !dir.empty(); dir = dir.parent_path()) {
    const fs::path p = dir / ".." / "shared" / "data" / name;
    if (fs::exists(p)) return p;
    if (dir == dir.parent_path()) break;
  }
  return candidate;
}

inline std::vector<uint8_t> readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// ---- a minimal independent scan of a well-formed file (no checks beyond what it needs) ----

struct ScanResult {
  std::vector<std::array<int32_t, 3>> sizes;
  uint64_t voxels = 0;
  std::array<uint64_t, 256> histogram{};
  std::array<int, 3> tightLo{255, 255, 255}, tightHi{-1, -1, -1};
  std::vector<std::array<uint8_t, 4>> rgba;  // raw entries, file order
  bool sceneGraph = false;
};

inline int32_t le32(const std::vector<uint8_t>& b, size_t at) {
  int32_t v;
  std::memcpy(&v, b.data() + at, 4);  // little-endian host (x86-64, aarch64)
  return v;
}

inline ScanResult scanVox(const std::vector<uint8_t>& b) {
  ScanResult r;
  const size_t childrenAt = 20 + size_t(le32(b, 12));
  const size_t end = childrenAt + size_t(le32(b, 16));
  for (size_t at = childrenAt; at < end;) {
    const std::string id(reinterpret_cast<const char*>(b.data() + at), 4);
    const size_t n = size_t(le32(b, at + 4)), m = size_t(le32(b, at + 8));
    const size_t c = at + 12;
    if (id == "SIZE") r.sizes.push_back({le32(b, c), le32(b, c + 4), le32(b, c + 8)});
    if (id == "XYZI") {
      const size_t count = size_t(le32(b, c));
      r.voxels += count;
      for (size_t i = 0; i < count; ++i) {
        const uint8_t* v = b.data() + c + 4 + 4 * i;
        ++r.histogram[v[3]];
        for (int a = 0; a < 3; ++a) {
          r.tightLo[size_t(a)] = std::min<int>(r.tightLo[size_t(a)], v[a]);
          r.tightHi[size_t(a)] = std::max<int>(r.tightHi[size_t(a)], v[a]);
        }
      }
    }
    if (id == "RGBA")
      for (size_t i = 0; i < 256; ++i) r.rgba.push_back({b[c + 4 * i], b[c + 4 * i + 1], b[c + 4 * i + 2], b[c + 4 * i + 3]});
    if (id == "nTRN" || id == "nGRP" || id == "nSHP") r.sceneGraph = true;
    at = c + n + m;
  }
  return r;
}

// ---- a test-only writer ----

struct Bytes {
  std::vector<uint8_t> b;
  Bytes& i32(int32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(uint8_t(uint32_t(v) >> (8 * i)));
    return *this;
  }
  Bytes& str(const std::string& s) {
    i32(int32_t(s.size()));
    b.insert(b.end(), s.begin(), s.end());
    return *this;
  }
  Bytes& dict(const std::vector<std::pair<std::string, std::string>>& kv) {
    i32(int32_t(kv.size()));
    for (const auto& [k, v] : kv) str(k).str(v);
    return *this;
  }
  Bytes& raw(const std::vector<uint8_t>& more) {
    b.insert(b.end(), more.begin(), more.end());
    return *this;
  }
};

using Blob = std::vector<uint8_t>;

inline Blob chunk(const std::string& id, const Blob& content, const Blob& children = {}) {
  Bytes out;
  out.b.assign(id.begin(), id.end());
  out.i32(int32_t(content.size())).i32(int32_t(children.size())).raw(content).raw(children);
  return out.b;
}

inline Blob voxFile(const std::vector<Blob>& mainChildren, int version = 150) {
  Blob children;
  for (const Blob& c : mainChildren) children.insert(children.end(), c.begin(), c.end());
  Bytes out;
  out.b = {'V', 'O', 'X', ' '};
  out.i32(version).raw(chunk("MAIN", {}, children));
  return out.b;
}

inline Blob sizeChunk(int x, int y, int z) { return chunk("SIZE", Bytes().i32(x).i32(y).i32(z).b); }
inline Blob xyziChunk(const std::vector<VoxVoxel>& voxels) {
  Bytes c;
  c.i32(int32_t(voxels.size()));
  for (const VoxVoxel& v : voxels) c.b.insert(c.b.end(), {v.x, v.y, v.z, v.colorIndex});
  return chunk("XYZI", c.b);
}
inline Blob rgbaChunk(const std::array<VoxRgba, 256>& byIndex) {
  Bytes c;
  for (int i = 1; i <= 256; ++i) {
    const VoxRgba p = byIndex[size_t(i & 255)];  // entry i - 1 is palette index i; the last is unused
    c.b.insert(c.b.end(), {p.r, p.g, p.b, p.a});
  }
  return chunk("RGBA", c.b);
}
inline Blob ntrn(int id, int child, const std::string& t = "", const std::string& r = "") {
  std::vector<std::pair<std::string, std::string>> frame;
  if (!r.empty()) frame.emplace_back("_r", r);
  if (!t.empty()) frame.emplace_back("_t", t);
  return chunk("nTRN", Bytes().i32(id).dict({{"_name", "t"}}).i32(child).i32(-1).i32(0).i32(1).dict(frame).b);
}
inline Blob ngrp(int id, const std::vector<int>& children) {
  Bytes c;
  c.i32(id).dict({}).i32(int32_t(children.size()));
  for (int ch : children) c.i32(ch);
  return chunk("nGRP", c.b);
}
inline Blob nshp(int id, int model) { return chunk("nSHP", Bytes().i32(id).dict({}).i32(1).i32(model).dict({}).b); }

// Parses an exact-size copy so that ASan catches any over-read.
inline VoxModelSet parseExact(const Blob& bytes, const std::string& name) {
  const Blob exact(bytes);
  return parseVox(exact.empty() ? nullptr : exact.data(), exact.size(), name);
}

inline void expectInvalid(const Blob& bytes, const std::string& name, const std::string& fragment) {
  try {
    parseExact(bytes, name);
    ADD_FAILURE() << name << ": expected InvalidInput containing \"" << fragment << "\"";
  } catch (const InvalidInput& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(name + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(fragment), std::string::npos) << "message: " << msg << "\nexpected: " << fragment;
  }
}

inline uint64_t countStoredVoxels(const Terrain& t, uint64_t* water = nullptr) {
  uint64_t n = 0, w = 0;
  t.voxels().forEachChunk([&](const Int3& c, const VoxelChunk& chunk) {
    for (int z = 0; z < kChunkSize; ++z)
      for (int y = 0; y < kChunkSize; ++y)
        for (int x = 0; x < kChunkSize; ++x) {
          const Voxel v = t.voxels().get({c.x * kChunkSize + x, c.y * kChunkSize + y, c.z * kChunkSize + z});
          if (!v.isAir()) ++n;
          if (v.isWater()) ++w;
        }
    (void)chunk;
  });
  if (water) *water = w;
  return n;
}

// A hand-built file with a scene graph (used by the scene and bad-file suites):
// root nTRN 0 (_t 1 1 1) -> nGRP 1 -> { nTRN 2 (_t 10 0 0) -> nSHP 3 (model 0),
//                                       nTRN 4 (_t -5 3 7) -> nSHP 5 (model 1) }
inline Blob twoModelScene() {
  return voxFile({sizeChunk(4, 4, 4), xyziChunk({{0, 0, 0, 10}, {3, 3, 3, 11}}),  //
                  sizeChunk(3, 5, 1), xyziChunk({{0, 0, 0, 20}, {2, 4, 0, 21}, {1, 2, 0, 22}}),
                  ntrn(0, 1, "1 1 1"), ngrp(1, {2, 4}), ntrn(2, 3, "10 0 0"), nshp(3, 0), ntrn(4, 5, "-5 3 7"),
                  nshp(5, 1)},
                 200);
}

}  // namespace bw::test::vox
