// The generators by name (each family lives in its own file: building_generators.cpp,
// vehicle_generators.cpp, station_generator.cpp, dock_generators.cpp; what they share in build_writer.h).
#include "collision/content/build_generators.h"

#include "collision/core/argument_checks.h"

namespace bw {

std::vector<std::string> buildNames() { return {"house", "truck", "carrier", "ring_station", "plate_stack", "city_block", "chain_link", "hangar"}; }

GeneratedBuild generateBuild(const std::string& name, uint64_t seed, float scale) {
  if (name == "house") return generateHouse(seed, scale);
  if (name == "truck") return generateTruck(seed, scale);
  if (name == "carrier") return generateCarrierShip(seed, scale);
  if (name == "ring_station") return generateRingStation(seed, scale);
  if (name == "plate_stack") return generatePlateStackBricks(seed, scale);
  if (name == "city_block") return generateCityBlock(seed, scale);
  if (name == "chain_link") return generateChainLink(seed, scale);
  if (name == "hangar") return generateHangar(seed, scale);
  std::string valid;
  for (const std::string& n : buildNames()) valid += (valid.empty() ? "" : ", ") + n;
  throw InvalidInput("generateBuild: name is \"" + name + "\", expected one of: " + valid);
}

}  // namespace bw
