#include "collision/content/brs_components.h"

#include <algorithm>
#include <string_view>

#include "collision/content/brs_format.h"

namespace bw::brs {
namespace {

// How a value of each property type is stored: a fixed number of bits, or a string.
struct PropertyType {
  std::string_view name;
  uint32_t bits;  // 0: a string (i32 length + bytes, not byte aligned)
};

// Every type Lighthouse_Island uses (checked: its two components decode to their last byte),
// plus the fixed-size numeric types public readers list (Integer, Integer64, Double,
// IntVector), which no save we have contains. Anything else cannot be sized, which leaves the
// rest of the component undecodable, so it is an error rather than a skip.
constexpr PropertyType kPropertyTypes[] = {
    {"Boolean", 32},                        // a 32-bit integer, 0 or 1
    {"Float", 32},     {"Integer", 32},     // IEEE float, i32
    {"Color", 32},                          // 4 bytes B, G, R, A
    {"Byte", 8},       {"Integer64", 64},  {"Double", 64},
    {"Rotator", 96},                        // 3 floats: pitch, yaw, roll (degrees)
    {"IntVector", 96},                      // 3 x i32
    {"Class", 0},      {"Object", 0},      {"String", 0},
};

const PropertyType* findType(std::string_view name) {
  for (const PropertyType& t : kPropertyTypes)
    if (t.name == name) return &t;
  return nullptr;
}

// An i32 count of items that take at least minItemBits each, checked against the bits left
// (a corrupt count fails here instead of looping or allocating ahead of the data).
uint32_t bitCount(BitReader& bits, const char* what, uint64_t minItemBits) {
  const int32_t n = bits.i32();
  if (n < 0) bits.failHere(std::string(what) + " is negative (" + std::to_string(n) + ")");
  if (uint64_t(n) > bits.bitsLeft() / minItemBits)
    bits.failHere(std::string(what) + " " + std::to_string(n) + " exceeds the data (" + std::to_string(bits.bitsLeft()) +
                  " bits left)");
  return uint32_t(n);
}

Component readComponent(const uint8_t* data, size_t size, std::string name, uint32_t brickCount, const std::string& file) {
  BitReader bits(data, size, file, "components: " + name);
  Component c;
  c.name = std::move(name);
  c.version = bits.i32();

  // Brick indices use the brick records' rule: uint(max(brickCount, 2)), at least one bit each.
  const uint64_t indexMax = std::max<uint64_t>(brickCount, 2);
  const uint32_t entries = bitCount(bits, "brick count", 1);
  c.bricks.reserve(entries);
  for (uint32_t k = 0; k < entries; ++k) {
    const uint32_t index = bits.uintBelow(indexMax);
    if (index >= brickCount)
      bits.failHere("brick index " + std::to_string(index) + " is out of range (" + std::to_string(brickCount) + " bricks)");
    c.bricks.push_back(index);
  }

  // Each property is two strings, at least two 32-bit lengths.
  const uint32_t propertyCount = bitCount(bits, "property count", 64);
  c.properties.reserve(propertyCount);
  std::vector<const PropertyType*> types;
  types.reserve(propertyCount);
  uint64_t minRowBits = 0;
  int radius = -1;
  for (uint32_t p = 0; p < propertyCount; ++p) {
    ComponentProperty prop;
    prop.name = bits.string("property name");
    prop.type = bits.string("property type");
    const PropertyType* t = findType(prop.type);
    if (!t) bits.failHere("property " + prop.name + " has type \"" + prop.type + "\", which cannot be sized");
    if (prop.name == "Radius" && prop.type == "Float") radius = int(p);
    minRowBits += t->bits ? t->bits : 32;
    types.push_back(t);
    c.properties.push_back(std::move(prop));
  }
  // note: minRowBits <= 96 * 2^31 and entries < 2^31, so the product cannot overflow.
  if (uint64_t(entries) * minRowBits > bits.bitsLeft())
    bits.failHere("truncated: " + std::to_string(entries) + " bricks of at least " + std::to_string(minRowBits) +
                  " bits of values exceed the " + std::to_string(bits.bitsLeft()) + " bits left");

  if (radius >= 0) c.radius.reserve(entries);
  for (uint32_t k = 0; k < entries; ++k) {
    for (uint32_t p = 0; p < propertyCount; ++p) {
      const PropertyType& t = *types[p];
      if (int(p) == radius) {
        c.radius.push_back(bits.f32());
      } else if (t.bits == 0) {
        bits.string("property value");
      } else {
        for (uint32_t left = t.bits; left > 0; left -= std::min<uint32_t>(left, 32)) bits.bits(int(std::min<uint32_t>(left, 32)));
      }
    }
  }
  // The writer pads the stream to a whole byte (Lighthouse_Island: 1 and 4 zero bits), so the
  // values end in the component's last byte. More left over means a type was sized wrongly.
  if (bits.bitsLeft() >= 8)
    bits.failHere(std::to_string(bits.bitsLeft()) + " bits left after the last value (a component ends within its last byte)");
  return c;
}

}  // namespace

std::vector<Component> readComponents(const std::vector<uint8_t>& bytes, uint32_t brickCount, const std::string& file) {
  BrsReader r(bytes.data(), bytes.size(), file, "components");
  // Each component takes at least its name's and its length's i32.
  const uint32_t n = r.count("components count", 8);
  std::vector<Component> out;
  out.reserve(n);
  for (uint32_t i = 0; i < n; ++i) {
    std::string name = r.string("component name");
    const int32_t len = r.i32("component length");
    if (len < 0) r.failHere(name + ": length is negative (" + std::to_string(len) + ")");
    if (size_t(len) > r.remaining())
      r.failHere(name + ": truncated: length " + std::to_string(len) + " exceeds the " + std::to_string(r.remaining()) +
                 " bytes left");
    const uint8_t* data = r.take(size_t(len), "component data");
    out.push_back(readComponent(data, size_t(len), std::move(name), brickCount, file));
  }
  // The section holds the components and nothing else (Lighthouse_Island: exactly).
  if (r.remaining() != 0) r.failHere(std::to_string(r.remaining()) + " bytes left after the last component");
  return out;
}

}  // namespace bw::brs
