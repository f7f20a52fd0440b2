// The .vox reader against bad files: each must fail with InvalidInput naming the file, never
// crash or half-load (truncated and corrupted real files included).
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <gtest/gtest.h>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "collision/content/brs_reader.h"
#include "collision/content/vox_reader.h"
#include "collision/core/argument_checks.h"
#include "collision/terrain/terrain.h"
#include "collision/content/vox_test_files.h"

namespace bw {
namespace {

using namespace test::vox;

// ---- bad files ----

TEST(VoxBadFiles, HeaderAndChunkProblemsNameTheFileAndTheProblem) {
  const Blob good = voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 1}})});
  ASSERT_NO_THROW(parseExact(good, "good.vox"));

  Blob magic = good;
  magic[0] = 'W';
  expectInvalid(magic, "magic.vox", "not a MagicaVoxel file");
  expectInvalid(voxFile({}, 151), "v151.vox", "unsupported version 151");
  expectInvalid(Blob{'V', 'O', 'X'}, "short.vox", "truncated");
  expectInvalid(Blob{}, "zero.vox", "truncated");
  Blob notMain = good;
  notMain[8] = 'X';
  expectInvalid(notMain, "notmain.vox", "expected \"MAIN\"");

  // MAIN's children size larger than the data.
  Blob mainTooBig = good;
  mainTooBig[16] += 4;
  expectInvalid(mainTooBig, "mainbig.vox", "MAIN chunk: truncated");
  // A child whose content exceeds MAIN.
  Blob childTooBig = good;
  childTooBig[20 + 4] = 200;  // SIZE content size
  expectInvalid(childTooBig, "childbig.vox", "exceed MAIN");
  Blob negative = good;
  negative[20 + 8 + 3] = 0x80;  // SIZE children size negative
  expectInvalid(negative, "negative.vox", "negative sizes");
  // Content shorter than its fields.
  expectInvalid(voxFile({chunk("SIZE", Bytes().i32(2).i32(2).b), xyziChunk({})}), "shortsize.vox",
                "SIZE chunk 0: truncated: size z");

  // XYZI count beyond the chunk.
  Blob count = voxFile({sizeChunk(2, 2, 2), chunk("XYZI", Bytes().i32(3).i32(0).i32(0).b)});
  expectInvalid(count, "count.vox", "XYZI chunk 1: numVoxels 3 exceeds the chunk");
  expectInvalid(voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 2, 0, 1}})}), "outside.vox",
                "voxel 0 at (0, 2, 0) is outside SIZE (2, 2, 2)");
  expectInvalid(voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 0}})}), "index0.vox", "colour index 0");
  expectInvalid(voxFile({sizeChunk(0, 2, 2), xyziChunk({})}), "size0.vox", "is outside [1, 256]");
  expectInvalid(voxFile({sizeChunk(2, 257, 2), xyziChunk({})}), "size257.vox", "is outside [1, 256]");
  expectInvalid(voxFile({xyziChunk({})}), "nosize.vox", "XYZI chunk without a SIZE");
  expectInvalid(voxFile({sizeChunk(2, 2, 2)}), "noxyzi.vox", "last SIZE chunk has no XYZI");
  expectInvalid(voxFile({sizeChunk(2, 2, 2), sizeChunk(2, 2, 2), xyziChunk({})}), "twosize.vox",
                "not followed by its XYZI");
  expectInvalid(voxFile({chunk("PACK", Bytes().i32(2).b), sizeChunk(2, 2, 2), xyziChunk({})}), "pack.vox",
                "numModels 2 but the file has 1");
  expectInvalid(voxFile({sizeChunk(2, 2, 2), xyziChunk({}), chunk("RGBA", Blob(100, 0))}), "rgba.vox",
                "RGBA chunk 2: truncated: palette");
}

TEST(VoxBadFiles, SceneGraphProblems) {
  const Blob model = voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 1}})});
  auto withNodes = [](std::vector<Blob> nodes) {
    std::vector<Blob> all = {sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 1}})};
    all.insert(all.end(), nodes.begin(), nodes.end());
    return voxFile(all);
  };
  ASSERT_NO_THROW(parseExact(withNodes({ntrn(0, 1), nshp(1, 0)}), "ok.vox"));
  expectInvalid(withNodes({ntrn(0, 7), nshp(1, 0)}), "missing.vox", "node 7 is referenced but missing");
  expectInvalid(withNodes({ntrn(1, 2), nshp(2, 0)}), "noroot.vox", "has no root node 0");
  expectInvalid(withNodes({ntrn(0, 1), ngrp(1, {2}), ntrn(2, 1)}), "cycle.vox", "cycle through node 1");
  expectInvalid(withNodes({ntrn(0, 0)}), "selfcycle.vox", "cycle through node 0");
  expectInvalid(withNodes({ntrn(0, 1), nshp(1, 3)}), "model.vox", "names model 3 of 1");
  expectInvalid(withNodes({ntrn(0, 1), nshp(1, 0), nshp(1, 0)}), "dup.vox", "node id 1 is used by an earlier nSHP");
  expectInvalid(withNodes({ntrn(0, 1, "1 2"), nshp(1, 0)}), "t2.vox", "_t \"1 2\" is not three integers");
  expectInvalid(withNodes({ntrn(0, 1, "1 2 x"), nshp(1, 0)}), "tx.vox", "is not three integers");
  expectInvalid(withNodes({ntrn(0, 1, "99999999 0 0"), nshp(1, 0)}), "tbig.vox", "is beyond");
  expectInvalid(withNodes({ntrn(0, 1, "", "3"), nshp(1, 0)}), "r3.vox", "is not a rotation");
  expectInvalid(withNodes({ntrn(0, 1, "", "200"), nshp(1, 0)}), "r200.vox", "not a rotation byte");
  // A DICT whose count exceeds the chunk.
  expectInvalid(withNodes({chunk("nGRP", Bytes().i32(0).i32(1000).b)}), "dict.vox", "exceeds the chunk");
  // Deep chains are refused before the stack suffers.
  std::vector<Blob> chain;
  for (int i = 0; i < 400; ++i) chain.push_back(ngrp(i, {i + 1}));
  chain.push_back(nshp(400, 0));
  expectInvalid(withNodes(chain), "deep.vox", "deeper than 256");
  // Exponential instancing is capped: 20 levels of groups with two edges to the same child.
  std::vector<Blob> fan;
  for (int i = 0; i < 20; ++i) fan.push_back(ngrp(i, {i + 1, i + 1}));
  fan.push_back(nshp(20, 0));
  expectInvalid(withNodes(fan), "fan.vox", "more than 65536 instances");
  // 65536 instances of a 16,385-voxel model place more than 2^30 voxels.
  std::vector<Blob> many = {sizeChunk(32, 32, 32), xyziChunk(std::vector<VoxVoxel>(16385, VoxVoxel{1, 2, 3, 4}))};
  for (int i = 0; i < 16; ++i) many.push_back(ngrp(i, {i + 1, i + 1}));
  many.push_back(nshp(16, 0));
  expectInvalid(voxFile(many), "many.vox", "places more than 1073741824 voxels");
  (void)model;
}

TEST(VoxBadFiles, TruncatedRealFilesAlwaysThrow) {
  for (const char* name : {"monu6.vox", "nature.vox"}) {
    const Blob full = readFile(dataPath(name));
    ASSERT_GT(full.size(), 1000u) << name;
    std::vector<size_t> cuts;
    for (size_t i = 0; i < 64; ++i) cuts.push_back(i);
    std::mt19937_64 rng(20261121);
    std::uniform_int_distribution<size_t> pick(0, full.size() - 1);
    for (int i = 0; i < 60; ++i) cuts.push_back(pick(rng));
    cuts.push_back(full.size() - 1);
    for (size_t cut : cuts)
      expectInvalid(Blob(full.begin(), full.begin() + long(cut)), std::string("cut_") + name, "truncated");
    // The same cuts with MAIN's children size patched to what is left, so that parsing reaches
    // the cut chunk. A cut exactly at a chunk boundary leaves a valid (smaller) file.
    int rejected = 0;
    for (size_t cut : cuts) {
      if (cut < 20) continue;
      Blob b(full.begin(), full.begin() + long(cut));
      const uint32_t children = uint32_t(cut - 20);
      for (int i = 0; i < 4; ++i) b[16 + size_t(i)] = uint8_t(children >> (8 * i));
      try {
        parseExact(b, std::string("patched_") + name);
      } catch (const InvalidInput& e) {
        EXPECT_EQ(std::string(e.what()).rfind(std::string("patched_") + name + ": ", 0), 0u) << e.what();
        ++rejected;
      }
    }
    EXPECT_GE(rejected, int(cuts.size()) - 20 - 3) << name;
  }
}

TEST(VoxBadFiles, CorruptedSceneFilesThrowOrParseNeverCrash) {
  // Every truncation of a scene-graph file, and random byte corruptions inside it: each parse
  // must either succeed or throw InvalidInput (ASan checks the reads).
  const Blob base = twoModelScene();
  for (size_t cut = 0; cut < base.size(); ++cut)
    expectInvalid(Blob(base.begin(), base.begin() + long(cut)), "cut_scene.vox", "");
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<size_t> pos(0, base.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  int parsed = 0, rejected = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    Blob b = base;
    const int flips = 1 + trial % 3;
    for (int f = 0; f < flips; ++f) b[pos(rng)] = uint8_t(byte(rng));
    try {
      const VoxModelSet s = parseExact(b, "flip.vox");
      ++parsed;
      if (!s.empty() && s.boundsMax.x - s.boundsMin.x < 4096 && s.boundsMax.y - s.boundsMin.y < 4096 &&
          s.boundsMax.z - s.boundsMin.z < 4096) (void)buildVoxTerrain(s);
    } catch (const InvalidInput&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_GT(parsed, 0);
}

TEST(VoxBadFiles, MissingFileNamesThePath) {
  try {
    loadVox("/nonexistent/dir/model.vox");
    ADD_FAILURE();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/model.vox: file: does not exist"), std::string::npos) << e.what();
  }
  // A directory is named as one (it read as "larger than 2 GiB"), for .vox and .brs alike.
  const std::string dir = ::testing::TempDir() + "bw_vox_dir_test.vox";
  std::filesystem::create_directories(dir);
  try {
    loadVox(dir);
    ADD_FAILURE();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(dir + ": file: is a directory, expected a MagicaVoxel .vox model"), std::string::npos) << e.what();
  }
  try {
    loadBrs(dir);
    ADD_FAILURE();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(dir + ": file: is a directory, expected a Brickadia .brs save"), std::string::npos) << e.what();
  }
  std::filesystem::remove(dir);
}

}  // namespace
}  // namespace bw
