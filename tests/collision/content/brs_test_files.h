#pragma once
// Helpers for the .brs reader suites (brs_reader_test.cpp, brs_components_test.cpp): the shared
// data folder, and a test-only writer for hand-built saves of versions 8 to 10 with bricks and
// components (written from the layout in brs_reader.h, independently of the reader).
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>
#include <zlib.h>

#include "collision/content/brs_reader.h"
#include "collision/core/argument_checks.h"

namespace bw::test::brsfile {

// The shared data folder is a sibling of the repository: <repo>/../shared/data.
inline std::filesystem::path lighthousePath() {
  namespace fs = std::filesystem;
  const fs::path repo = fs::path(__FILE__).parent_path().parent_path().parent_path().parent_path();
  const fs::path candidate = repo / ".." / "shared" / "data" / "Lighthouse_Island.brs";
  if (fs::exists(candidate)) return candidate;
  for (fs::path dir = fs::current_path(); !dir.empty(); dir = dir.parent_path()) {
    const fs::path p = dir / ".." / "shared" / "data" / "Lighthouse_Island.brs";
    if (fs::exists(p)) return p;
    if (dir == dir.parent_path()) break;
  }
  return candidate;
}

// Lighthouse_Island loaded once per test binary: the suites parse the 1.3 MB file many times already.
inline const BrsLoadResult& lighthouse() {
  static const BrsLoadResult r = loadBrs(lighthousePath().string());
  return r;
}

inline std::vector<uint8_t> readFile(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Writes bits least significant first, like the game.
struct BitWriter {
  std::vector<uint8_t> bytes;
  uint64_t bit = 0;
  void put(bool v) {
    if ((bit >> 3) >= bytes.size()) bytes.push_back(0);
    if (v) bytes[size_t(bit >> 3)] |= uint8_t(1u << (bit & 7));
    ++bit;
  }
  void bits(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) put((v >> i) & 1);
  }
  void align() { bit = (bit + 7) & ~uint64_t(7); }
  void uintBelow(uint64_t v, uint64_t max) {
    uint64_t value = 0;
    for (uint64_t mask = 1; value + mask < max; mask <<= 1) {
      put(v & mask);
      if (v & mask) value |= mask;
    }
  }
  void packed(uint64_t v) {
    do {
      const uint64_t part = v & 127;
      v >>= 7;
      put(v != 0);
      bits(part, 7);
    } while (v != 0);
  }
  void signedPacked(int64_t v) { packed((uint64_t(v < 0 ? -v : v) << 1) | (v >= 0 ? 1 : 0)); }
  void i32(int32_t v) { bits(uint32_t(v), 32); }
  void f32(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    bits(u, 32);
  }
  // A Latin-1 string (length with the NUL), or UTF-16 (negative length, no NUL) — unaligned.
  void str(const std::string& s) {
    i32(int32_t(s.size() + 1));
    for (char c : s) bits(uint8_t(c), 8);
    bits(0, 8);
  }
  void str16(const std::string& s) {
    i32(-int32_t(s.size()));
    for (char c : s) bits(uint8_t(c), 16);
  }
};

struct Bytes {
  std::vector<uint8_t> b;
  void u8(uint8_t v) { b.push_back(v); }
  void i32(int32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(uint8_t(uint32_t(v) >> (8 * i)));
  }
  void str(const std::string& s) {
    i32(int32_t(s.size() + 1));
    b.insert(b.end(), s.begin(), s.end());
    b.push_back(0);
  }
  void zeros(size_t n) { b.insert(b.end(), n, 0); }
  void append(const std::vector<uint8_t>& o) { b.insert(b.end(), o.begin(), o.end()); }
  // A section, zlib-compressed when that makes it smaller (as the game writes them).
  void section(const std::vector<uint8_t>& raw) {
    std::vector<uint8_t> z(compressBound(uLong(raw.size())));
    uLongf zn = uLongf(z.size());
    compress(z.data(), &zn, raw.data(), uLong(raw.size()));
    i32(int32_t(raw.size()));
    if (zn < raw.size()) {
      i32(int32_t(zn));
      b.insert(b.end(), z.begin(), z.begin() + long(zn));
    } else {
      i32(0);
      append(raw);
    }
  }
};

// ---- components ----

// One component as the test writes it. Values are written by type: Boolean 1, Float 2.5
// (Radius: radius[k]), Color 0xFF3366CC, Byte 7, Rotator (10, 20, 30), Class/Object/String
// text (Latin-1, or UTF-16 for a property named "Wide"); any other type writes nothing. The
// overrides corrupt the data on purpose.
struct TestComponent {
  std::string name{};
  std::vector<uint32_t> bricks{};
  std::vector<std::pair<std::string, std::string>> properties{};  // name, type
  std::vector<float> radius{};                                     // per brick, for "Radius"
  std::optional<int32_t> brickCountOverride{};                     // stored brick count
  std::optional<int32_t> propertyCountOverride{};                  // stored property count
  int32_t lengthDelta = 0;  // < 0: the data is cut short (stored and written); > 0: length claims more
  int extraBits = 0;        // zero bits appended after the values
};

inline std::vector<std::pair<std::string, std::string>> pointLightProperties() {
  return {{"bMatchBrickShape", "Boolean"}, {"Brightness", "Float"},     {"Radius", "Float"},
          {"Color", "Color"},              {"bUseBrickColor", "Boolean"}, {"bCastShadows", "Boolean"}};
}
inline std::vector<std::pair<std::string, std::string>> spotLightProperties() {
  return {{"Rotation", "Rotator"}, {"InnerConeAngle", "Float"}, {"OuterConeAngle", "Float"},
          {"Brightness", "Float"}, {"Radius", "Float"},         {"Color", "Color"},
          {"bUseBrickColor", "Boolean"}, {"bCastShadows", "Boolean"}};
}

// The bit stream of one component (before any length cut).
inline std::vector<uint8_t> componentData(const TestComponent& c, uint32_t brickCount) {
  BitWriter w;
  w.i32(1);  // version
  w.i32(c.brickCountOverride.value_or(int32_t(c.bricks.size())));
  for (uint32_t i : c.bricks) w.uintBelow(i, std::max<uint64_t>(brickCount, 2));
  w.i32(c.propertyCountOverride.value_or(int32_t(c.properties.size())));
  for (const auto& [name, type] : c.properties) {
    w.str(name);
    w.str(type);
  }
  for (size_t k = 0; k < c.bricks.size(); ++k)
    for (const auto& [name, type] : c.properties) {
      if (type == "Boolean") w.bits(1, 32);
      else if (type == "Float") w.f32(name == "Radius" ? c.radius.at(k) : 2.5f);
      else if (type == "Color") w.bits(0xFF3366CCu, 32);
      else if (type == "Byte") w.bits(7, 8);
      else if (type == "Rotator") {
        w.f32(10.f);
        w.f32(20.f);
        w.f32(30.f);
      } else if (type == "Class" || type == "Object" || type == "String") {
        if (name == "Wide") w.str16("wide text " + std::to_string(k));
        else w.str("text for brick " + std::to_string(k));
      }
    }
  w.bits(0, c.extraBits);
  return w.bytes;
}

// The components section's raw bytes.
inline std::vector<uint8_t> componentsSection(const std::vector<TestComponent>& components, uint32_t brickCount) {
  Bytes s;
  s.i32(int32_t(components.size()));
  for (const TestComponent& c : components) {
    std::vector<uint8_t> data = componentData(c, brickCount);
    s.str(c.name);
    if (c.lengthDelta < 0) data.resize(data.size() - std::min(data.size(), size_t(-c.lengthDelta)));
    s.i32(int32_t(data.size()) + std::max(0, c.lengthDelta));
    s.append(data);
  }
  return s.b;
}

// Components for a save of n bricks: point lights on bricks 2, 5, 8, ... (radius 150, 250, ...),
// a spot light on brick 0 (radius 1000), and an interaction component on the last brick whose
// strings (Latin-1 and UTF-16) put the following values off byte alignment.
inline std::vector<TestComponent> sampleComponents(uint32_t n) {
  TestComponent point{.name = "BCD_PointLight", .properties = pointLightProperties()};
  for (uint32_t i = 2; i < n; i += 3) {
    point.bricks.push_back(i);
    point.radius.push_back(150.f + 100.f * float(point.radius.size()));
  }
  TestComponent spot{.name = "BCD_SpotLight", .properties = spotLightProperties()};
  TestComponent interact{.name = "BCD_Interact",
                         .properties = {{"bPlayInteractSound", "Boolean"}, {"Message", "String"}, {"Wide", "String"},
                                        {"Tag", "Byte"}, {"Target", "Class"}, {"Owner", "Object"}}};
  if (n > 0) {
    spot.bricks = {0};
    spot.radius = {1000.f};
    interact.bricks = {n - 1};
  }
  return {point, spot, interact};
}

// ---- bricks and whole saves ----

struct TestBrick {
  uint32_t asset;
  bool hasSize;
  uint32_t size[3];
  int32_t pos[3];
  int direction, rotation;
  bool collision;
};

// A whole save; `components` is the components section's raw bytes (default:
// componentsSection(sampleComponents(bricks.size()))).
inline std::vector<uint8_t> buildSave(int version, const std::vector<std::string>& assets, const std::vector<TestBrick>& bricks,
                                      int32_t brickCountOverride = -1,
                                      const std::optional<std::vector<uint8_t>>& components = std::nullopt) {
  Bytes f;
  f.b = {'B', 'R', 'S'};
  f.u8(uint8_t(version));
  f.u8(0);
  f.i32(1234);
  Bytes h1;
  h1.str("TestMap");
  h1.str("Tester");
  h1.str("a save built by the test");
  h1.zeros(16);
  h1.str("Host");
  h1.zeros(16);
  h1.zeros(8);
  h1.i32(brickCountOverride >= 0 ? brickCountOverride : int32_t(bricks.size()));
  f.section(h1.b);
  Bytes h2;
  h2.i32(0);  // mods
  h2.i32(int32_t(assets.size()));
  for (const auto& a : assets) h2.str(a);
  h2.i32(3);  // colors
  h2.zeros(12);
  h2.i32(2);  // materials
  h2.str("BMC_Plastic");
  h2.str("BMC_Glow");
  h2.i32(1);  // owners
  h2.zeros(16);
  h2.str("Tester");
  h2.i32(int32_t(bricks.size()));
  if (version >= 9) {
    h2.i32(1);
    h2.str("BPMC_Default");
  }
  f.section(h2.b);
  f.u8(0);  // no preview
  BitWriter w;
  for (size_t i = 0; i < bricks.size(); ++i) {
    const TestBrick& t = bricks[i];
    w.align();
    w.uintBelow(t.asset, std::max<uint64_t>(assets.size(), 2));
    w.put(t.hasSize);
    if (t.hasSize)
      for (uint32_t s : t.size) w.packed(s);
    for (int32_t p : t.pos) w.signedPacked(p);
    w.uintBelow(uint64_t(t.direction * 4 + t.rotation), 24);
    if (version >= 10) {
      w.put(t.collision);
      w.bits(0b111, 3);  // weapon, interaction, tool on: only the player bit decides
    } else {
      w.put(t.collision);
    }
    w.put(true);           // visible
    w.uintBelow(1, 2);     // material
    if (version >= 9) {
      w.uintBelow(0, 2);   // physical material
      w.uintBelow(5, 11);  // intensity
    }
    if (i % 2) {
      w.put(true);
      w.bits(0x00ABCDEF, version >= 9 ? 24 : 32);
    } else {
      w.put(false);
      w.uintBelow(2, 3);
    }
    w.packed(1);  // owner 0
  }
  f.section(w.bytes);
  f.section(components ? *components : componentsSection(sampleComponents(uint32_t(bricks.size())), uint32_t(bricks.size())));
  return f.b;
}

inline const std::vector<std::string> kAssets = {"PB_DefaultBrick", "PB_DefaultSideWedgeTile", "B_1x1_Round", "B_Mystery",
                                                 "PB_DefaultArch",  "PB_DefaultWedge"};

inline std::vector<TestBrick> sampleBricks() {
  return {
      {0, true, {10, 20, 6}, {0, 0, 6}, 4, 0, true},           // 2x4 brick, default orientation
      {1, true, {15, 5, 2}, {-100, 40, 2}, 4, 1, true},        // side wedge tile, quarter turn
      {2, false, {0, 0, 0}, {50, -50, 18}, 0, 2, true},        // round 1x1 lying along +X
      {3, false, {0, 0, 0}, {7, 8, 9}, 5, 3, true},            // unknown fixed asset
      {4, true, {5, 30, 12}, {0, 300, 12}, 2, 0, true},        // unknown procedural asset
      {5, true, {20, 10, 12}, {1000, 0, -12}, 1, 1, false},    // wedge, collision off
      {0, true, {1, 1, 1}, {-70000, 123456, -999}, 3, 2, true},
  };
}

// Parses a copy of exactly `bytes` (so ASan sees any over-read) and expects a clear failure
// whose message contains the file name and every fragment.
inline void expectInvalid(const std::vector<uint8_t>& bytes, const std::string& name,
                          std::initializer_list<std::string> fragments) {
  std::vector<uint8_t> exact(bytes);
  exact.shrink_to_fit();
  try {
    parseBrs(exact.empty() ? nullptr : exact.data(), exact.size(), name);
    ADD_FAILURE() << name << ": expected InvalidInput containing \"" << *fragments.begin() << "\"";
  } catch (const InvalidInput& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(name), std::string::npos) << msg;
    for (const std::string& fragment : fragments) EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
  }
}
inline void expectInvalid(const std::vector<uint8_t>& bytes, const std::string& name, const std::string& fragment) {
  expectInvalid(bytes, name, {fragment});
}

}  // namespace bw::test::brsfile
