#pragma once
/// Reader for MagicaVoxel files (.vox, versions 150 and 200) and the step that turns the models
/// into a voxel terrain.
///
///   bw::VoxModelSet set = bw::loadVox("../shared/data/monu6.vox");
///   bw::VoxTerrain t = bw::buildVoxTerrain(set, bw::VoxMaterialMap::monu6(), {.voxelSize = 0.5f});
///   t.terrain->overlapLocal(box);
///
/// Everything is read from one buffer; every read is checked against the bytes left in its
/// chunk, and a bad file throws bw::InvalidInput("<file>: <chunk>: <problem>") before anything is
/// returned (the whole file is parsed into locals first), so a caller never sees a half-loaded set.
///
/// ## File layout (all integers little endian, int = i32)
/// ```
/// "VOX " int version (150 or 200)
/// chunk MAIN, whose children are (in any order, SIZE immediately followed by its XYZI):
///   PACK  int numModels                       optional; must equal the SIZE/XYZI pairs
///   SIZE  int x, y, z                         model size, z is up (each in [1, kVoxMaxModelSize])
///   XYZI  int n, then n x (u8 x, y, z, colorIndex)   coordinates < SIZE, colorIndex 1..255
///   RGBA  256 x (u8 r, g, b, a): entry i is palette index i + 1 (the last entry is unused)
///   nTRN  int node, DICT attrs, int child, int reserved (-1), int layer, int frames,
///         frames x DICT (_t "x y z" translation, _r rotation byte, _f frame)
///   nGRP  int node, DICT attrs, int n, n x int child
///   nSHP  int node, DICT attrs, int n, n x (int model, DICT attrs)
///   anything else (MATL, LAYR, rOBJ, rCAM, NOTE, IMAP, MATT, ...) is skipped by its sizes
/// chunk    = 4-byte id, int contentBytes N, int childBytes M, N bytes content, M bytes children
/// STRING   = int n, n bytes (no NUL);  DICT = int n, n x (STRING key, STRING value)
/// ```
/// Children must fit inside their parent and contents inside the chunk; bytes after MAIN are
/// ignored. Without an RGBA chunk the default palette applies: a 6 x 6 x 6 colour cube (channel
/// values FF CC 99 66 33 00, blue varying fastest, then green, then red; black dropped) in
/// indices 1..215, then ten-step ramps EE DD BB AA 88 77 55 44 22 11 of red (216..225), green
/// (226..235), blue (236..245) and grey (246..255), all opaque; index 0 is transparent black.
/// It is generated, not copied, and the tests compare it with the table in the format text.
///
/// ## Placement (scene graph)
/// The root is node 0. Every path root -> ... -> nSHP is one instance of the shape's model (the
/// first model listed in the shape: further ones are animation frames). The translation `_t` of
/// frame 0 (the first frame listed) of every nTRN on the path is summed. MagicaVoxel puts a
/// model's centre at that translation: model voxel v lands at
///     v + translation - floor(size / 2)        (per axis, size > 0 so floor is integer division)
/// Without nTRN/nGRP/nSHP chunks (version 150 files such as monu6 and nature) the model is one
/// instance with its voxel coordinates unchanged (model voxel (0,0,0) at the origin); several
/// models there are an animation's frames, and only the first is placed (animationFrames).
/// Rotations `_r` are NOT applied: a non-identity `_r` on a path is counted in
/// VoxModelSet::ignoredRotations and marks the instance `rotationIgnored`; the model is placed
/// unrotated at its translation. `_hidden` nodes and layers are placed like visible ones.
/// Nodes that no path reaches are ignored. Missing nodes, duplicate node ids, cycles, paths deeper
/// than kVoxMaxSceneDepth, more than kVoxMaxInstances instances or kVoxMaxPlacedVoxels placed
/// voxels, and shapes naming missing models are errors.
///
/// ## Axes
/// MagicaVoxel's z is up ("gravity direction" in the format text), as in our world: x, y, z are
/// kept as they are, in the terrain and in every coordinate reported here.
///
/// ## Materials (VoxMaterialMap)
/// Palette index -> terrain material, first match wins: an override from `overrides` (e.g. read
/// from a JSON mapping file), then the water range [waterFirst, waterLast] -> kMaterialWater, then
/// the solid rule: PerPaletteIndex gives material min(paletteIndex + 1, 255) (index 1 -> 2,
/// 254 -> 255, 255 also -> 255: one collision, there are 255 used indices and 254 solid ids),
/// Single gives `solidMaterial`. Material 0 (air) from an override skips those voxels.
///
/// ## Water in monu6.vox
/// monu6 has no MATL chunks (version 150), so water was found from the palette: its voxels use
/// eight indices, and 29 and 31 are the only blue ones, both (144, 223, 227) cyan; index 30 is
/// grey (226, 226, 226) and unused. Index 31 fills a 76 x 76 box at z 6..45 (the pool around the
/// monument, 169,072 voxels), index 29 an 8 x 24 x 24 column at z 62..85 (a fountain, 2,118
/// voxels). VoxMaterialMap::monu6() therefore makes [29, 31] water (171,190 voxels).
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "collision/core/rigid_transform.h"
#include "collision/terrain/terrain.h"

namespace bw {

/// Largest model size per axis: XYZI coordinates are bytes, so no voxel can lie beyond 256.
inline constexpr int32_t kVoxMaxModelSize = 256;
/// Largest |translation| per axis along one path (keeps placed coordinates far inside int32 and
/// inside a terrain's 2^24 voxels per axis).
inline constexpr int32_t kVoxMaxTranslation = 1 << 22;
/// Longest root -> shape path (MagicaVoxel writes 4 levels per group nesting level).
inline constexpr int kVoxMaxSceneDepth = 256;
/// Most instances a scene graph may expand to (shared subtrees multiply paths).
inline constexpr uint32_t kVoxMaxInstances = 1u << 16;
/// Most voxels all instances together may place (2^30: a 1024^3 block; bounds the terrain build).
inline constexpr uint64_t kVoxMaxPlacedVoxels = uint64_t(1) << 30;

/// One palette colour.
struct VoxRgba {
  uint8_t r = 0, g = 0, b = 0, a = 0;
  constexpr bool operator==(const VoxRgba&) const = default;
};

/// One voxel as stored in XYZI: model coordinates and palette index (1..255).
struct VoxVoxel {
  uint8_t x = 0, y = 0, z = 0, colorIndex = 0;
  constexpr bool operator==(const VoxVoxel&) const = default;
};

/// One SIZE/XYZI pair.
struct VoxModel {
  Int3 size;                     ///< voxels per axis, each in [1, kVoxMaxModelSize]
  std::vector<VoxVoxel> voxels;  ///< in file order
};

/// One placement of a model (one root -> nSHP path, or one model when there is no scene graph).
struct VoxInstance {
  uint32_t model = 0;        ///< index into VoxModelSet::models
  Int3 translation;          ///< summed `_t` along the path (0 without a scene graph)
  Int3 offset;               ///< where model voxel (0,0,0) lands: translation - floor(size/2)
  bool rotationIgnored = false;  ///< the path had a non-identity `_r` (not applied)
};

/// What a .vox file holds, placed.
struct VoxModelSet {
  int version = 0;                         ///< 150 or 200
  std::vector<VoxModel> models;            ///< SIZE/XYZI pairs in file order
  std::vector<VoxInstance> instances;      ///< placements, in scene-graph depth-first order
  std::array<VoxRgba, 256> palette{};      ///< indexed by colorIndex; [0] unused
  bool defaultPalette = true;              ///< no RGBA chunk: the default palette applies
  bool hasSceneGraph = false;              ///< nTRN/nGRP/nSHP chunks were present
  uint64_t fileVoxels = 0;                 ///< voxels in all XYZI chunks
  uint64_t totalVoxels = 0;                ///< voxels placed (over instances; overlaps counted twice)
  std::array<uint64_t, 256> paletteCounts{};  ///< placed voxels per palette index
  Int3 boundsMin, boundsMax;               ///< union of the instances' model boxes, inclusive, voxel units
  Int3 voxelBoundsMin, voxelBoundsMax;     ///< tight bounds of the placed voxels, inclusive (min > max: none)
  uint32_t transformsApplied = 0;          ///< nTRN visits on the instance paths (identity ones included)
  uint32_t ignoredRotations = 0;           ///< nTRN nodes with a non-identity `_r` on some instance path
  uint32_t skippedChunks = 0;              ///< MAIN children not used (MATL, LAYR, rOBJ, ...)
  /// Animation frames (1: none). A file without a scene graph holding several models is an
  /// animation of MagicaVoxel 0.98 and earlier (one model a frame): only model 0 is placed (the
  /// frames stacked in one place gave 10,219 voxels where 1,655 distinct ones exist). With a
  /// scene graph: the most models a shape lists or frames a transform lists; frame 0 is placed.
  uint32_t animationFrames = 1;

  /// Placed voxels whose palette index lies in [first, last].
  uint64_t countInRange(int first, int last) const;
  /// True when no voxel was placed.
  bool empty() const { return totalVoxels == 0; }
};

/// Reads a .vox file. Throws InvalidInput naming the file, the chunk and the problem.
VoxModelSet loadVox(const std::string& path);

/// The same from bytes in memory; nameForErrors starts every error message.
VoxModelSet parseVox(const uint8_t* data, size_t size, const std::string& nameForErrors);

/// MagicaVoxel's default palette (see the header comment), indexed by colorIndex.
const std::array<VoxRgba, 256>& voxDefaultPalette();

/// Palette index -> terrain material (see "Materials" above).
struct VoxMaterialMap {
  enum class Solids : uint8_t {
    PerPaletteIndex,  ///< material min(paletteIndex + 1, 255)
    Single,           ///< every solid index gets solidMaterial
  };
  int waterFirst = 1;  ///< first palette index that is water (inclusive)
  int waterLast = 0;   ///< last palette index that is water (inclusive); < waterFirst: no water
  Solids solids = Solids::PerPaletteIndex;
  uint8_t solidMaterial = kMaterialFirstSolid;  ///< used by Solids::Single (must be >= 2)
  std::array<int16_t, 256> overrides;           ///< -1: use the rules; 0..255: this material

  VoxMaterialMap() { overrides.fill(-1); }
  /// The map for monu6.vox: palette indices 29..31 are water.
  static VoxMaterialMap monu6();
  /// Material of a palette index (0 = air: the voxel is skipped).
  uint8_t materialFor(uint8_t paletteIndex) const;
  /// True when paletteIndex maps to water.
  bool isWater(uint8_t paletteIndex) const { return materialFor(paletteIndex) == kMaterialWater; }
};

/// Reads a mapping file (JSON):
/// ```
/// { "water": [29, 31],                  optional inclusive palette range
///   "solids": "per_index" | "single",   optional, default per_index
///   "solid_material": 2,                optional, for "single" (2..255)
///   "materials": { "45": 7, "11": 0 } } optional overrides: palette index (1..255) -> material
/// ```
/// Throws InvalidInput naming the file and the bad entry.
VoxMaterialMap loadVoxMaterialMap(const std::string& path);
/// The same from text; nameForErrors starts every error message.
VoxMaterialMap parseVoxMaterialMap(const std::string& jsonText, const std::string& nameForErrors);

/// How buildVoxTerrain sizes and places the terrain.
struct VoxTerrainOptions {
  float voxelSize = 1.0f;                 ///< edge of one voxel in terrain-local units
  RigidTransform placement{};             ///< terrain-local -> world
  int32_t margin = 2;                     ///< voxels of air around the model bounds, per side (>= 0)
  size_t cacheBudgetBytes = Terrain::kDefaultCacheBudget;  ///< narrowphase cache budget
};

/// A terrain built from a .vox model set.
struct VoxTerrain {
  std::unique_ptr<Terrain> terrain;  ///< sized to the model bounds plus the margin
  Int3 voxToTerrain;                 ///< add to a placed .vox coordinate to get the terrain voxel index
  uint64_t solidVoxels = 0;          ///< voxels written as solid (later instances overwrite earlier)
  uint64_t waterVoxels = 0;          ///< voxels written as water
  uint64_t skippedVoxels = 0;        ///< voxels whose palette index maps to air
};

/// Builds a terrain from the placed voxels with one Terrain::edit. Every voxel is written with
/// full occupancy; where instances overlap the later one wins (counts are of writes, so the
/// stored totals can be lower). Throws InvalidInput for a bad option (margin < 0, solid material
/// < 2) or what the Terrain constructor rejects.
VoxTerrain buildVoxTerrain(const VoxModelSet& set, const VoxMaterialMap& materials = {},
                           const VoxTerrainOptions& options = {});

}  // namespace bw
