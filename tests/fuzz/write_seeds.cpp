// Writes the generated part of the fuzz seed corpora (tests/fuzz/README.md): small .brs saves
// of versions 8 to 10 and .vox files with and without a scene graph, from the test suites'
// independent writers, and seeded random programs for the edit targets. Run once to refresh
// tests/fuzz/corpus; the files it writes are checked in.
//   write_fuzz_seeds tests/fuzz/corpus
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "collision/content/brs_test_files.h"
#include "collision/content/vox_test_files.h"

namespace fs = std::filesystem;

namespace {

void write(const fs::path& file, const std::vector<uint8_t>& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  std::printf("%s (%zu bytes)\n", file.string().c_str(), bytes.size());
}

void brsSeeds(const fs::path& dir) {
  using namespace bw::test::brsfile;
  for (int version : {8, 9, 10}) write(dir / ("seed_v" + std::to_string(version) + ".brs"), buildSave(version, kAssets, sampleBricks()));
  write(dir / "seed_one_brick.brs", buildSave(10, {"PB_DefaultBrick"}, {{0, true, {5, 5, 6}, {0, 0, 6}, 4, 0, true}}));
  write(dir / "seed_no_components.brs", buildSave(10, kAssets, sampleBricks(), -1, componentsSection({}, 7)));
}

void voxSeeds(const fs::path& dir) {
  using namespace bw::test::vox;
  std::vector<bw::VoxVoxel> cube;
  for (uint8_t i = 0; i < 4; ++i)
    for (uint8_t j = 0; j < 4; ++j) cube.push_back({i, j, uint8_t((i + j) % 4), uint8_t(1 + i * 4 + j)});
  write(dir / "seed_plain.vox", voxFile({sizeChunk(4, 4, 4), xyziChunk(cube)}));
  std::array<bw::VoxRgba, 256> palette{};
  for (int i = 0; i < 256; ++i) palette[size_t(i)] = {uint8_t(i), uint8_t(255 - i), uint8_t(i * 7), 255};
  write(dir / "seed_palette.vox", voxFile({sizeChunk(4, 4, 4), xyziChunk(cube), rgbaChunk(palette)}));
  write(dir / "seed_scene_graph.vox",
        voxFile({sizeChunk(4, 4, 4), xyziChunk(cube), sizeChunk(2, 3, 4), xyziChunk({{1, 2, 3, 9}, {0, 0, 0, 200}}),
                 ntrn(0, 1), ngrp(1, {2, 4}), ntrn(2, 3, "10 -4 2"), nshp(3, 0), ntrn(4, 5, "-8 0 0", "17"), nshp(5, 1)},
                200));
  write(dir / "seed_animation.vox", voxFile({sizeChunk(4, 4, 4), xyziChunk(cube), sizeChunk(4, 4, 4), xyziChunk({{3, 3, 3, 5}})}));
}

// Programs for the edit targets: seeded random bytes of a few lengths (every byte string is a
// valid program; these give the fuzzer long ones to start from).
void programSeeds(const fs::path& dir, uint32_t seed) {
  std::mt19937 rng(seed);
  for (size_t length : {64u, 512u, 4096u}) {
    std::vector<uint8_t> bytes(length);
    for (uint8_t& b : bytes) b = uint8_t(rng());
    write(dir / ("seed_random_" + std::to_string(length)), bytes);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_fuzz_seeds CORPUS_DIR (tests/fuzz/corpus)\n");
    return 2;
  }
  const fs::path root(argv[1]);
  brsSeeds(root / "brs");
  voxSeeds(root / "vox");
  programSeeds(root / "octobvh_edits", 1);
  programSeeds(root / "grid_edits", 2);
  return 0;
}
