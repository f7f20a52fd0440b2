#pragma once
/// The components section of a .brs save: which bricks carry which component (a point light, a
/// spot light, ...) and the property values stored for each of them. Internal to the reader; the
/// layout is documented in brs_reader.h.
///
/// Each component's data is a bit stream whose length is stored in front of it. The decoder reads
/// every value by its declared type and then requires the stream to end within one byte (the
/// padding to a whole byte), so a wrong guess about any type's size cannot pass silently.
#include <cstdint>
#include <string>
#include <vector>

namespace bw::brs {

/// A property as the component declares it.
struct ComponentProperty {
  std::string name;  ///< "Radius", "Brightness", ...
  std::string type;  ///< Unreal type name: "Float", "Color", "Boolean", ...
};

/// One decoded component.
struct Component {
  std::string name;                           ///< "BCD_PointLight", "BCD_SpotLight", ...
  int32_t version = 0;                        ///< the component's own data version (1 in Lighthouse_Island)
  std::vector<ComponentProperty> properties;  ///< in stored order
  std::vector<uint32_t> bricks;               ///< record indices (file order) of the bricks carrying it, as stored
  /// The "Radius" property (type Float) of each entry of `bricks`; empty when the component has
  /// no such property. Raw values in Brickadia units, not checked (the caller decides).
  std::vector<float> radius;
};

/// Decodes the components section (the section's uncompressed bytes). brickCount is header 1's.
/// Throws InvalidInput("<file>: components: <problem>") for bad framing (including bytes after
/// the last component) and
/// InvalidInput("<file>: components: <component name>: <problem>") for bad component data: a
/// count beyond the data, a brick index >= brickCount, a property type we cannot size, a value
/// stream that is truncated or ends more than 7 bits before the component's stored length.
std::vector<Component> readComponents(const std::vector<uint8_t>& bytes, uint32_t brickCount, const std::string& file);

}  // namespace bw::brs
