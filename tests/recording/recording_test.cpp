// Recordings: every frame's recorded poses and states are the world's, recording changes no
// state hash, the recorded edits replayed on the recorded grids give the run's grids (splits
// included), the recorded terrain chunks follow the carves, bad files are refused with what is
// wrong named (and never crash: seeded corruption), and the page embeds the recording.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <zlib.h>

#include "collision/core/errors.h"
#include "collision/terrain/chunk_mesher.h"
#include "recording/recording_reader.h"
#include "recording/recording_writer.h"
#include "recording/viewer_page.h"
#include "world/scene_file.h"

namespace bw {
namespace {

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("bw_recording_test_" + std::to_string(::getpid()) + "_" + name)).string();
}

SceneDescription scene(const std::string& name, uint32_t frames) {
  SceneDescription s = loadScene(std::string(BW_SCENES_DIR) + "/" + name + ".json");
  s.settings.frames = frames;
  return s;
}

Vec3f relative(const Vec3d& p, const Vec3d& origin) { return (p - origin).cast<float>(); }

TEST(Recording, PosesAndStatesAreTheWorldsEveryFrameAndTheHashIsUnchanged) {
  const SceneDescription s = scene("crates_on_grid", 90);  // the first crates land at ~frame 40
  const std::string path = tempPath("poses.bwr");
  World world(s, 2);
  World plain(s, 2);
  std::vector<std::vector<Vec3d>> positions;
  std::vector<std::vector<Quatf>> rotations;
  std::vector<std::vector<uint8_t>> asleep;
  {
    RecordingOptions o;
    o.contacts = true;
    RecordingWriter rec(world, path, o, 2);
    ContainmentTracker inside(world);
    for (uint32_t f = 0; f < s.settings.frames; ++f) {
      world.step();
      plain.step();
      rec.frame(world, inside.update());
      positions.push_back(world.bodies().position);
      rotations.push_back(world.bodies().rotation);
      asleep.emplace_back();
      for (uint32_t b = 0; b < world.bodies().size(); ++b) asleep.back().push_back(world.asleep(b));
    }
    rec.finish();
  }
  EXPECT_EQ(world.stateHash(), plain.stateHash()) << "recording changed the simulation";
  const Recording r = readRecording(path);
  ASSERT_TRUE(r.complete);
  ASSERT_EQ(r.frames.size(), s.settings.frames);
  EXPECT_EQ(r.head.at("scene"), s.name);
  EXPECT_EQ(r.grids.size(), world.gridCount());
  ASSERT_EQ(r.bodies.size(), world.bodies().size());
  uint32_t sleepers = 0, contacts = 0;
  for (uint32_t f = 0; f < r.frames.size(); ++f) {
    const RecordedFrame& rf = r.frames[f];
    EXPECT_EQ(rf.bodyCount, world.bodies().size());
    uint32_t k = 0;
    for (uint32_t b = 0; b < world.bodies().size(); ++b) {
      if (world.bodies().motion[b] == MotionType::Static) continue;
      ASSERT_LT(k, rf.ids.size());
      ASSERT_EQ(rf.ids[k], b);
      EXPECT_EQ(rf.positions[k], relative(positions[f][b], r.origin)) << "frame " << f << " body " << b;
      EXPECT_EQ(rf.rotations[k].coeffs(), rotations[f][b].coeffs());
      EXPECT_EQ(rf.states[k] == RecordedState::Asleep, asleep[f][b] != 0) << "frame " << f << " body " << b;
      sleepers += rf.states[k] == RecordedState::Asleep;
      ++k;
    }
    EXPECT_EQ(k, rf.ids.size());
    contacts += rf.contacts;
    EXPECT_EQ(rf.stageMs.size(), RecordingWriter::stageNames().size());
  }
  EXPECT_GT(contacts, 0u) << "crates rest on the grid: the contacts must be recorded";
  // The grid is recorded brick by brick (under the limit) with its OctoBVH boxes.
  ASSERT_EQ(r.grids[0].bricks.size(), world.grid(0).brickCount());
  ASSERT_EQ(r.grids[0].nodeLevels.size(), 5u);
  EXPECT_LE(r.grids[0].nodeLevels[0].size(), 8u);
  EXPECT_GT(r.grids[0].nodeLevels[4].size(), r.grids[0].nodeLevels[0].size());
  std::filesystem::remove(path);
}

// Replays the recorded edits on the recorded grids; each grid from the frame it appeared in.
std::vector<std::map<uint32_t, Brick>> replayGrids(const Recording& r) {
  std::vector<std::map<uint32_t, Brick>> grids(r.grids.size());
  for (uint32_t g = 0; g < r.grids.size(); ++g)
    for (size_t k = 0; k < r.grids[g].bricks.size(); ++k) grids[g][r.grids[g].brickIds[k]] = r.grids[g].bricks[k];
  for (uint32_t f = 0; f < r.frames.size(); ++f)
    for (const RecordedEdit& e : r.frames[f].edits) {
      if (r.grids[e.grid].frame >= int32_t(f)) continue;  // its GRID block already holds this frame's state
      if (e.placed) {
        EXPECT_FALSE(grids[e.grid].count(e.brick)) << "frame " << f << ": placed over a live brick";
        grids[e.grid][e.brick] = e.value;
      } else {
        EXPECT_TRUE(grids[e.grid].count(e.brick)) << "frame " << f << ": removed a brick that is not there";
        grids[e.grid].erase(e.brick);
      }
    }
  return grids;
}

bool sameBrick(const Brick& a, const Brick& b) { return std::memcmp(&a, &b, sizeof(Brick)) == 0; }

// The recording's edits replayed on its grids give every grid of the world as it is now.
void expectReplayGivesTheWorldsGrids(const Recording& r, const World& world) {
  const auto grids = replayGrids(r);
  for (uint32_t g = 0; g < world.gridCount(); ++g) {
    std::map<uint32_t, Brick> live;
    world.grid(g).forEachBrick([&](uint32_t id) { live[id] = world.grid(g).brick(id); });
    ASSERT_EQ(grids[g].size(), live.size()) << "grid " << g << " (" << world.gridName(g) << ")";
    for (const auto& [id, b] : live) {
      ASSERT_TRUE(grids[g].count(id)) << "grid " << g << " brick " << id;
      EXPECT_TRUE(sameBrick(grids[g].at(id), b)) << "grid " << g << " brick " << id;
    }
  }
}

TEST(Recording, EditsReplayedOnTheRecordedGridsGiveTheRunsGridsThroughSplits) {
  const SceneDescription s = scene("demolition", 120);
  const std::string path = tempPath("demolition.bwr");
  World world(s, 2);
  uint32_t splits = 0, edited = 0;
  {
    RecordingWriter rec(world, path, {}, 2);
    ContainmentTracker inside(world);
    for (uint32_t f = 0; f < s.settings.frames; ++f) {
      world.step();
      splits += world.lastStats().splits;
      edited += world.lastStats().bricksRemoved + world.lastStats().bricksPlaced;
      rec.frame(world, inside.update());
    }
    rec.finish();
  }
  ASSERT_GT(splits, 0u) << "the scene must split within the frames tested";
  const Recording r = readRecording(path);
  uint32_t recordedSplits = 0, recordedEdits = 0;
  for (const RecordedFrame& f : r.frames) {
    recordedSplits += f.splits;
    recordedEdits += uint32_t(f.edits.size());
  }
  EXPECT_EQ(recordedSplits, splits);
  EXPECT_GE(recordedEdits, edited);  // the load's edits, then the bricks parts took along
  ASSERT_EQ(r.grids.size(), world.gridCount());
  ASSERT_EQ(r.bodies.size(), world.bodies().size());
  expectReplayGivesTheWorldsGrids(r, world);
  // Bodies made by splits appear in the frame of their split, as dynamic grid bodies.
  for (uint32_t b = 0; b < r.bodies.size(); ++b)
    if (r.bodies[b].frame >= 0) {
      EXPECT_EQ(r.bodies[b].kind, RecordedKind::Grid);
      EXPECT_EQ(r.bodies[b].motion, MotionType::Dynamic);
    }
  std::filesystem::remove(path);
}

// Edits a game makes between steps: World::editGrid() (seen by the world only as "this grid
// changed") and World::removeBricks() (which may split parts off). Both worlds get the same edits;
// the recorded one must replay to the run's grids and its hash must equal the other's.
TEST(Recording, EditsThroughEditGridAndRemoveBricksBetweenStepsAreRecorded) {
  const SceneDescription s = scene("demolition", 60);
  const std::string path = tempPath("between_steps.bwr");
  World world(s, 2);
  World plain(s, 2);
  uint32_t g = 0;  // the grid with the most bricks
  for (uint32_t k = 1; k < world.gridCount(); ++k)
    if (world.grid(k).brickCount() > world.grid(g).brickCount()) g = k;
  std::mt19937 rng(20261125);
  const auto someLive = [&](const BrickGrid& grid) {
    std::vector<uint32_t> ids;
    grid.forEachBrick([&](uint32_t id) { ids.push_back(id); });
    return ids[std::uniform_int_distribution<size_t>(0, ids.size() - 1)(rng)];
  };
  uint32_t splits = 0, handEdits = 0, removals = 0;
  {
    RecordingWriter rec(world, path, {}, 2);
    ContainmentTracker inside(world);
    for (uint32_t f = 0; f < s.settings.frames; ++f) {
      if (f % 10 == 3) {
        // Remove two bricks, put one back 100 m up (a loose brick: a later removal splits it
        // off), and one back where it was (its id may be used again: seen as a change).
        const uint32_t a = someLive(world.grid(g)), b = someLive(world.grid(g));
        for (World* w : {&world, &plain}) {  // the same ids in both: the worlds are equal
          BrickGrid& grid = w->editGrid(g);
          const Brick ba = grid.brick(a), bb = grid.brick(b);
          grid.removeBrick(a);
          if (b != a) grid.removeBrick(b);
          Brick up = ba;
          up.position.z() += 100.f;
          grid.placeBrick(up);
          if (b != a) grid.placeBrick(bb);
        }
        handEdits += 4;
      }
      if (f % 10 == 6) {
        const uint32_t ids[2] = {someLive(world.grid(g)), someLive(world.grid(g))};
        const uint32_t n = ids[0] == ids[1] ? 1 : 2;
        splits += world.removeBricks(g, std::span<const uint32_t>(ids, n)).parts;
        plain.removeBricks(g, std::span<const uint32_t>(ids, n));
        removals += n;
      }
      world.step();
      plain.step();
      splits += world.lastStats().splits;
      rec.frame(world, inside.update());
    }
    rec.finish();
  }
  ASSERT_GT(handEdits + removals, 0u);
  EXPECT_GT(splits, 0u) << "the loose bricks placed 100 m up must split off at a removal";
  EXPECT_EQ(world.stateHash(), plain.stateHash()) << "recording changed the simulation";
  const Recording r = readRecording(path);
  uint32_t recordedSplits = 0;
  for (const RecordedFrame& f : r.frames) recordedSplits += f.splits;
  EXPECT_EQ(recordedSplits, splits) << "removeBricks()' splits belong to the next frame's recording";
  ASSERT_EQ(r.grids.size(), world.gridCount());
  expectReplayGivesTheWorldsGrids(r, world);
  std::filesystem::remove(path);
}

TEST(Recording, NodeBoxesAreRecordedToTheChosenDepth) {
  const SceneDescription s = scene("crates_on_grid", 1);
  for (const int levels : {1, 2, 6}) {
    const std::string path = tempPath("depth.bwr");
    World world(s, 1);
    {
      RecordingOptions o;
      o.nodeLevels = levels;
      RecordingWriter rec(world, path, o, 1);
      world.step();
      rec.frame(world, {});
      rec.finish();
    }
    const Recording r = readRecording(path);
    ASSERT_FALSE(r.grids.empty());
    ASSERT_EQ(r.grids[0].nodeLevels.size(), size_t(levels));
    size_t most = 1;
    for (int k = 0; k < levels; ++k) {
      most *= 8;
      EXPECT_LE(r.grids[0].nodeLevels[k].size(), most) << "level " << k + 1;
      EXPECT_GT(r.grids[0].nodeLevels[k].size(), k ? r.grids[0].nodeLevels[k - 1].size() : 0u) << "level " << k + 1;
    }
    std::filesystem::remove(path);
  }
}

TEST(Recording, TerrainChunksFollowTheCarvesAndSlabsBecomeGridBodies) {
  const SceneDescription s = scene("quarry", 200);
  const std::string path = tempPath("quarry.bwr");
  World world(s, 2);
  uint32_t parts = 0;
  {
    RecordingWriter rec(world, path, {}, 2);
    ContainmentTracker inside(world);
    for (uint32_t f = 0; f < s.settings.frames; ++f) {
      world.step();
      parts += world.lastStats().terrainParts;
      rec.frame(world, inside.update());
    }
    rec.finish();
  }
  ASSERT_GT(parts, 0u) << "the quarry must break slabs free within the frames tested";
  const Recording r = readRecording(path);
  ASSERT_EQ(r.terrainTriangles.size(), world.terrainCount());
  uint32_t changed = 0;
  for (const RecordedFrame& f : r.frames) changed += f.terrainChunks;
  EXPECT_GT(changed, 0u);
  for (uint32_t t = 0; t < world.terrainCount(); ++t) {
    const Terrain& terrain = world.terrain(t);
    std::map<uint64_t, uint32_t> now;
    ChunkNeighbourhood n;
    ChunkMesh mesh;
    terrain.voxels().forEachChunk([&](const Int3& c, const VoxelChunk&) {
      terrain.voxels().gatherNeighbourhood(c, n);
      meshChunk(n, terrain.voxelSize(), mesh);
      now[chunkKey(c)] = mesh.triangleCount();
    });
    std::map<uint64_t, uint32_t> recorded;
    for (const auto& [key, triangles] : r.terrainTriangles[t])
      if (triangles) recorded[key] = triangles;
    std::erase_if(now, [](const auto& kv) { return kv.second == 0; });
    EXPECT_EQ(recorded, now) << "terrain " << t << ": the recorded chunks are not the terrain's meshes at the end";
  }
  EXPECT_EQ(r.grids.size(), world.gridCount());
  EXPECT_EQ(r.bodies.size(), world.bodies().size());
  std::filesystem::remove(path);
}

// A small complete recording's decompressed bytes.
std::vector<uint8_t> smallRecording() {
  const std::string path = tempPath("small.bwr");
  SceneDescription s = scene("stack10", 3);
  World world(s, 1);
  {
    RecordingOptions o;
    o.contacts = true;
    RecordingWriter rec(world, path, o, 1);
    ContainmentTracker inside(world);
    for (int f = 0; f < 3; ++f) {
      world.step();
      rec.frame(world, inside.update());
    }
    rec.finish();
  }
  std::vector<uint8_t> bytes = readRecordingBytes(path);
  std::filesystem::remove(path);
  return bytes;
}

TEST(Recording, SubmissionModeTimesAndInsideSolidStatesAreKept) {
  const std::string path = tempPath("modes.bwr");
  World world(scene("stack10", 4), 1);
  {
    RecordingWriter rec(world, path, {}, 1);
    ContainmentTracker inside(world);
    for (int f = 0; f < 4; ++f) {
      world.step();
      // Frame 2 says the last body is inside solid (as a tracker would): recorded as such.
      ContainmentReport report = inside.update();
      if (f == 2) report.bodies.push_back(world.bodies().size() - 1);
      rec.frame(world, report);
    }
    const std::vector<double> update{0.5, 0.25, 0.125, 1}, other{1, 2, 3, 4}, short_{1, 2};
    rec.submissionMode("per-object mutex", update, other, other, other);
    EXPECT_THROW(rec.submissionMode("bad", short_, other, other, other), InvalidInput);
    rec.finish();
  }
  const Recording r = readRecording(path);
  ASSERT_EQ(r.modes.size(), 1u);
  EXPECT_EQ(r.modes[0].name, "per-object mutex");
  EXPECT_EQ(r.modes[0].updateMs, (std::vector<float>{0.5f, 0.25f, 0.125f, 1.f}));
  EXPECT_EQ(r.modes[0].waitMs, (std::vector<float>{1, 2, 3, 4}));
  for (uint32_t f = 0; f < 4; ++f) {
    ASSERT_EQ(r.frames[f].ids.back(), world.bodies().size() - 1);
    EXPECT_EQ(r.frames[f].states.back() == RecordedState::InsideSolid, f == 2) << "frame " << f;
  }
  std::filesystem::remove(path);
}

std::string errorOf(const std::vector<uint8_t>& bytes) {
  try {
    parseRecording(bytes, "x.bwr");
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

// Offset of the first block with this tag (after the 12-byte preamble).
size_t blockAt(const std::vector<uint8_t>& b, uint32_t tag) {
  size_t at = 12;
  while (at + 8 <= b.size()) {
    uint32_t t, n;
    std::memcpy(&t, &b[at], 4);
    std::memcpy(&n, &b[at + 4], 4);
    if (t == tag) return at;
    at += 8 + n;
  }
  return 0;
}

TEST(Recording, BadFilesAreRefusedWithWhatIsWrongNamed) {
  const std::vector<uint8_t> good = smallRecording();
  EXPECT_NO_THROW(parseRecording(good, "good"));
  auto broken = good;
  broken[0] = 'X';
  EXPECT_NE(errorOf(broken).find("not a brickworld recording"), std::string::npos) << errorOf(broken);
  broken = good;
  broken[8] = 9;
  EXPECT_NE(errorOf(broken).find("version 9"), std::string::npos) << errorOf(broken);
  // A brick's rotation byte out of range (the first brick of the first GRID).
  broken = good;
  const size_t grid = blockAt(good, kTagGrid);
  ASSERT_GT(grid, 0u);
  uint32_t nameLength;
  std::memcpy(&nameLength, &good[grid + 12], 4);
  const size_t firstBrick = grid + 8 + 8 + nameLength + 8;
  broken[firstBrick + 4 + 29] = 24;
  EXPECT_NE(errorOf(broken).find("brick rotation 24"), std::string::npos) << errorOf(broken);
  EXPECT_NE(errorOf(broken).find("GRID"), std::string::npos) << "the block is named: " << errorOf(broken);
  // A non-finite pose.
  broken = good;
  const size_t frame = blockAt(good, kTagFrame);
  const float nan = std::nanf("");
  const size_t firstPose = frame + 8 + 4 + 4 * RecordingWriter::stageNames().size() + 8;
  std::memcpy(&broken[firstPose + 4], &nan, 4);
  EXPECT_NE(errorOf(broken).find("position is not finite"), std::string::npos) << errorOf(broken);
  // A block length past the end of a complete file's stream is cut off: frames kept, not complete.
  broken.assign(good.begin(), good.begin() + long(blockAt(good, kTagEnd)));
  const Recording cut = parseRecording(broken, "cut");
  EXPECT_FALSE(cut.complete);
  EXPECT_EQ(cut.frames.size(), 3u);
  // END_ claiming other frames.
  broken = good;
  broken[blockAt(good, kTagEnd) + 8] = 7;
  EXPECT_NE(errorOf(broken).find("says 7 frames"), std::string::npos) << errorOf(broken);

  // Seeded corruption: every damaged file is read or refused with InvalidInput, nothing else.
  std::mt19937 rng(20261125);
  for (int k = 0; k < 3000; ++k) {
    auto b = good;
    const int flips = 1 + int(rng() % 4);
    for (int i = 0; i < flips; ++i) b[12 + rng() % (b.size() - 12)] = uint8_t(rng());
    if (k % 5 == 0) b.resize(12 + rng() % (b.size() - 12));
    try {
      parseRecording(b, "damaged");
    } catch (const InvalidInput&) {
    }
  }
}

TEST(Recording, ThePageEmbedsTheRecordingAndThreeJs) {
  const std::vector<uint8_t> bytes = smallRecording();
  const std::string path = tempPath("page.bwr"), page = tempPath("page.html");
  {
    gzFile f = gzopen(path.c_str(), "wb");
    ASSERT_TRUE(f);
    gzwrite(f, bytes.data(), unsigned(bytes.size()));
    gzclose(f);
  }
  const ViewerPageStats st = writeViewerPage(path, page, defaultThreeJsDir());
  EXPECT_EQ(st.frames, 3u);
  EXPECT_TRUE(st.complete);
  std::ifstream in(page);
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("QldSRUNPUkQ"), std::string::npos) << "the recording (BWRECORD in base64) is embedded";
  EXPECT_NE(html.find("OrbitControls"), std::string::npos);
  for (const char* mark : {"{{STYLE}}", "{{THREE}}", "{{DATA}}", "{{SCRIPT}}"})
    EXPECT_EQ(html.find(mark), std::string::npos) << mark << " was not filled in";
  EXPECT_EQ(html.find("src=\"http"), std::string::npos) << "nothing is fetched at view time";
  try {
    writeViewerPage(path, page, "/nonexistent/three");
    ADD_FAILURE() << "no three.js: must be refused";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("libjs-three"), std::string::npos) << e.what();
  }
  try {
    writeViewerPage(tempPath("missing.bwr"), page, defaultThreeJsDir());
    ADD_FAILURE() << "a missing recording must be refused";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("missing.bwr"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
  std::filesystem::remove(page);
}

}  // namespace
}  // namespace bw
