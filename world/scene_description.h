#pragma once
/// A parsed, validated scene: only what the scene declares (grids, spawners, settings). The
/// world builds exactly this and nothing else. Produced by loadScene (scene_file.h); the JSON
/// schema is documented in profiles/scenes/README.md.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "collision/brick.h"
#include "collision/math_types.h"

namespace bw {

/// How a body moves.
enum class MotionType : uint8_t { Static, Kinematic, Dynamic };

/// Scripted motion of a kinematic body: constant velocities (world frame).
struct KinematicMotion {
  Vec3d linearVelocity = Vec3d::Zero();
  Vec3f angularVelocity = Vec3f::Zero();  ///< rad/s about the body's centre
};

/// One grid: bricks from a generator or listed explicitly, and its placement.
struct GridDescription {
  std::string name;
  std::string generator;           ///< one of buildNames(), or empty for `bricks`
  float scale = 1.f;
  uint64_t seed = 1;
  std::vector<Brick> bricks;       ///< explicit bricks (when no generator)
  Vec3d position = Vec3d::Zero();
  Quatf rotation = Quatf::Identity();
  MotionType motion = MotionType::Static;
  KinematicMotion kinematic;
};

/// Dynamic primitives (or copies of a small grid) spawned in a box region.
struct SpawnerDescription {
  enum class Shape : uint8_t { Sphere, Box, Capsule, Grid };
  Shape shape = Shape::Box;
  std::string grid;                ///< template grid name when shape == Grid
  uint32_t count = 0;
  Vec3f halfExtents = Vec3f::Constant(0.25f);  ///< Box
  float radius = 0.25f;                         ///< Sphere, Capsule
  float halfHeight = 0.25f;                     ///< Capsule
  float density = 1.f;
  Vec3d regionMin = Vec3d::Zero(), regionMax = Vec3d::Zero();
  Vec3d velocity = Vec3d::Zero();
  uint64_t seed = 1;
};

/// Global settings of a run.
struct SceneSettings {
  Vec3d gravity{0, 0, -9.81};
  double timestep = 1.0 / 60.0;  ///< seconds per frame
  int substeps = 1;
  int solverIterations = 8;
  uint32_t frames = 300;
  float lodFraction = 1.f / 16;
  int approximationDepth = 3;
  bool sleeping = true;
};

struct SceneDescription {
  std::string name;
  std::string source;  ///< file it came from
  SceneSettings settings;
  std::vector<GridDescription> grids;
  std::vector<SpawnerDescription> spawners;
};

}  // namespace bw
