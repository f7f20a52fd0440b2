#include "cli/scene_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sys/resource.h>
#include <vector>

#include "cli/progress_watch.h"
#include "cli/render_figures.h"
#include "cli/series.h"
#include "cli/output_check.h"
#include "recording/recording_writer.h"
#include "world/bullet_baseline.h"
#include "world/scene_checks.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw::cli {

namespace {

double peakResidentMiB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

}  // namespace

std::string resolveScenePath(const std::string& scene) {
  if (std::filesystem::exists(scene)) return scene;
  const std::string shipped = std::string(BW_SOURCE_DIR) + "/profiles/scenes/" + scene + ".json";
  if (std::filesystem::exists(shipped)) return shipped;
  throw SceneError(scene + ": no such scene file, and no shipped scene of that name in " + BW_SOURCE_DIR + "/profiles/scenes");
}

// Deepest penetration among the last substep's contacts (m; 0 without any).
float deepestContact(const World& world) {
  float deepest = 0;
  for (uint32_t k = 0; k < world.pairs().size(); ++k)
    for (const Contact& c : world.pairContacts(k)) deepest = std::max(deepest, c.depth);
  return deepest;
}

// The first bodies of a containment report with where they are and why.
nlohmann::json insideSolidList(const ContainmentReport& inside, const std::vector<Vec3d>& positions) {
  nlohmann::json list = nlohmann::json::array();
  for (uint32_t k = 0; k < inside.count() && k < 20; ++k) {
    const Vec3d& p = positions[inside.bodies[k]];
    list.push_back({{"body", inside.bodies[k]}, {"why", insideSolidName(inside.reasons[k])}, {"position", {p.x(), p.y(), p.z()}}});
  }
  return list;
}

// The scene's own checks (scene_checks.h) as JSON: links kept, grids where they should end.
nlohmann::json checksJson(const SceneCheckTracker& checks) {
  const LinkCheckReport& l = checks.links();
  nlohmann::json j{{"pass", checks.pass()}};
  if (l.pairs)
    j["linked"] = {{"pairs", l.pairs}, {"parted_at_end", l.partedNow}, {"ever_parted", l.everParted},
                   {"first_parted_frame", l.firstPartedFrame}, {"first_parted", l.firstParted}};
  for (const EndsInReport& e : checks.endsIn())
    j["ends_in"].push_back({{"grid", e.grid}, {"inside", e.inside}, {"position", {e.position.x(), e.position.y(), e.position.z()}}});
  return j;
}

void printChecks(const SceneCheckTracker& checks) {
  if (!checks.any()) return;
  const LinkCheckReport& l = checks.links();
  if (l.pairs) {
    std::printf("  check linked: %u of %u neighbouring grids ever parted", l.everParted, l.pairs);
    if (l.everParted) std::printf(" (first %s at frame %u), %u apart at the end", l.firstParted.c_str(), l.firstPartedFrame, l.partedNow);
    std::printf("\n");
  }
  for (const EndsInReport& e : checks.endsIn())
    std::printf("  check ends_in: %s %s its box, at (%.2f, %.2f, %.2f)\n", e.grid.c_str(), e.inside ? "ended in" : "did NOT end in",
                e.position.x(), e.position.y(), e.position.z());
  std::printf("  scene checks: %s\n", checks.pass() ? "pass" : "FAIL");
}

// The same scene in Bullet from a fresh World's initial state (bullet_baseline.h). The fresh
// World is also the judge of Bullet's accuracy: it is moved to Bullet's poses after every frame
// and its containment tracker counts Bullet's bodies inside solid as it counts ours (except
// bodies our World spawned inside solid: they stay kinematic in the judge, which never steps,
// and the tracker follows dynamic bodies only). Returns the median frame time.
double runBullet(const SceneDescription& scene, int threads, BulletSetup setup, float chunkSize, KinematicGrids kinematic,
                 uint32_t frames, bool json, nlohmann::json& out) {
  using Clock = std::chrono::steady_clock;
  SceneDescription judged = scene;
  judged.attachments = AttachmentsDescription{};  // the judge only answers containment queries
  World judge(judged, threads);
  BulletBaseline bullet(judge, setup, chunkSize, kinematic);
  ContainmentTracker containment(judge);
  SceneCheckTracker checks(judge);
  std::vector<Vec3d> positions;
  std::vector<Quatf> rotations;
  Series total;
  uint64_t contacts = 0, rays = 0, rayHits = 0;
  float deepest = 0, endDeepest = 0;
  const char* label = setup == BulletSetup::Expert ? "bullet" : "bullet-naive";
  // Edits: the judge makes the scene's edit load on its grids at Bullet's poses, and Bullet
  // makes the same bricks' edits on its compounds. What to edit (the load's choosing) and the
  // connectivity search are game-side work done by the same code for both engines: their time
  // is counted in Bullet's frame as it is in ours; our grids' own edits and parts are not.
  const bool edits = !scene.edits.empty();
  judge.recordEdits(edits);
  Series editTimes;
  uint64_t bricksEdited = 0;
  for (uint32_t f = 0; f < frames; ++f) {
    double gameSideMs = 0;
    if (edits) {
      judge.applyFrameEdits();
      const StepStats& e = judge.lastStats();
      gameSideMs = e.editLoadMs + e.splitMs - e.partBodiesMs;
      bricksEdited += e.bricksRemoved + e.bricksPlaced;
    }
    const auto t = Clock::now();
    if (edits) bullet.applyEdits(judge);
    bullet.step();
    total.v.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t).count() + gameSideMs);
    if (edits) editTimes.v.push_back(bullet.lastEditSeconds() * 1e3);
    const BulletFrame figures = bullet.lastFrame();
    contacts += figures.contacts;
    rays += figures.rays;
    rayHits += figures.rayHits;
    endDeepest = figures.deepest;
    deepest = std::max(deepest, figures.deepest);
    bullet.poses(positions, rotations);
    judge.setPoses(positions, rotations);
    containment.update();
    checks.update();
    if (!json && frames >= 100 && (f + 1) % (frames / 10) == 0)
      std::fprintf(stderr, "  %s frame %u/%u  %.2f ms\n", label, f + 1, frames, total.v.back());
  }
  uint32_t resting, moving;
  double lowest;
  bullet.restingReport(resting, moving, lowest);
  const ContainmentReport& inside = containment.report();
  char chunk[32];
  std::snprintf(chunk, sizeof chunk, "%g", double(chunkSize));
  const std::string how = setup == BulletSetup::Expert
                              ? std::string("static grids as ") + chunk + " m chunk compounds, kinematic grids as " +
                                    (bullet.kinematicGrids() == KinematicGrids::ChunkBodies ? "a body per chunk" : "one compound") +
                                    ", CCD, split impulse"
                              : "each grid one btCompoundShape of one box per brick, no CCD";
  out = {{"engine", label},
         {"setup", how},
         {"chunk_objects", bullet.chunkObjects()},
         {"distinct_brick_shapes", bullet.distinctBrickShapes()},
         {"build_ms", bullet.buildSeconds() * 1e3},
         {"frame", {{"median_ms", total.quantile(0.5)}, {"p95_ms", total.quantile(0.95)}, {"max_ms", total.max()}}},
         {"contacts_per_frame", double(contacts) / frames},
         {"dynamic_resting", resting},
         {"dynamic_moving", moving},
         {"lowest_dynamic_z", std::isfinite(lowest) ? lowest : 0.0},
         {"bodies_inside_solid", inside.count()},
         {"max_penetration_m", deepest},
         {"end_penetration_m", endDeepest}};
  if (setup == BulletSetup::Expert) {
    out["chunk_m"] = chunkSize;
    out["kinematic_grids"] = kinematicGridsName(bullet.kinematicGrids());
  }
  if (edits) {
    out["edit"] = {{"median_ms", editTimes.quantile(0.5)}, {"max_ms", editTimes.max()},
                   {"us_per_brick", editTimes.sum() * 1e3 / double(std::max<uint64_t>(bricksEdited, 1))},
                   {"bricks_edited", bricksEdited}, {"parts_made", bullet.partsMade()}};
  }
  if (inside.count()) out["inside_solid"] = insideSolidList(inside, positions);
  if (checks.any()) out["checks"] = checksJson(checks);
  if (rays) {
    out["rays_per_frame"] = double(rays) / frames;
    out["ray_hit_share"] = double(rayHits) / double(rays);
  }
  if (!json) {
    std::printf("%s (btDiscreteDynamicsWorld, %s): built in %.0f ms\n", label, how.c_str(), bullet.buildSeconds() * 1e3);
    std::printf("  frame       %7.3f ms %7.3f ms %7.3f ms   (median, p95, max)\n", total.quantile(0.5), total.quantile(0.95), total.max());
    if (edits)
      std::printf("  edits       %7.3f ms %7.3f ms           (median, max per frame: chunk children, AABBs, masses, wakes, parts), "
                  "%.2f us per brick, %u parts made\n",
                  editTimes.quantile(0.5), editTimes.max(), editTimes.sum() * 1e3 / double(std::max<uint64_t>(bricksEdited, 1)),
                  bullet.partsMade());
    std::printf("  per frame: %.0f contacts", double(contacts) / frames);
    if (rays) std::printf(", %.0f rays (%.1f%% hit)", double(rays) / frames, 100.0 * double(rayHits) / double(rays));
    std::printf("\n  dynamic bodies at the end: %u resting, %u moving, lowest at z = %.2f\n", resting, moving,
                std::isfinite(lowest) ? lowest : 0.0);
    std::printf("  bodies inside solid at the end: %u; deepest contact %.1f mm over the run, %.1f mm in the last frame\n",
                inside.count(), deepest * 1e3, endDeepest * 1e3);
    printChecks(checks);
  }
  return total.quantile(0.5);
}

// The Bullet setups an --engine value asks for.
std::vector<BulletSetup> bulletSetups(const std::string& engine) {
  if (engine == "bullet" || engine == "both") return {BulletSetup::Expert};
  if (engine == "bullet-naive") return {BulletSetup::Naive};
  if (engine == "all") return {BulletSetup::Expert, BulletSetup::Naive};
  return {};
}

SubmissionMode submissionModeFromName(const std::string& name) {
  if (name == "batched" || name == "all") return SubmissionMode::Batched;
  if (name == "mutex") return SubmissionMode::PerObjectMutexNoRadius;
  if (name == "concurrent") return SubmissionMode::PerObjectConcurrentNoRadius;
  throw std::invalid_argument("--submission must be batched, mutex, concurrent or all (got '" + name + "')");
}

int runScene(const SceneRunOptions& o) {
  using Clock = std::chrono::steady_clock;
  const std::string path = resolveScenePath(o.scene);
  SceneDescription scene = loadScene(path);
  if (!o.sleeping.empty()) scene.settings.sleeping = o.sleeping == "on";
  const std::vector<BulletSetup> setups = bulletSetups(o.engine);
  if (o.engine != "brickworld" && setups.empty())
    throw std::invalid_argument("--engine must be brickworld, bullet, bullet-naive, both or all (got '" + o.engine + "')");
  for (BulletSetup setup : setups) BulletBaseline::requireMirrorable(scene, setup);  // refuse before running ours
  if (o.engine == "bullet" || o.engine == "bullet-naive") {
    if (!o.recordPath.empty())
      throw std::invalid_argument("--record records brickworld's run; --engine " + o.engine + " runs only Bullet (use --engine both)");
    nlohmann::json b;
    runBullet(scene, o.threads, setups[0], o.bulletChunk, kinematicGridsFromName(o.bulletKinematic), o.frames ? o.frames : scene.settings.frames, o.json, b);
    if (o.json) std::cout << nlohmann::json{{"scene", scene.name}, {"engine", o.engine}, {"bullet", b}}.dump(2) << "\n";
    return 0;
  }
  const std::string submissionName = o.submission.empty() ? "batched" : o.submission;
  const SubmissionMode submission = submissionModeFromName(submissionName);
  if (!o.submission.empty() && !scene.attachments.enabled)
    throw SceneError(path + ": --submission " + o.submission + ": the scene declares no attachments (no render thread to submit to)");
  requireWritable(o.tracePath, "--trace");
  requireWritable(o.csvPath, "--csv");
  requireWritable(o.recordPath, "--record");
  ProgressWatch watch(o.progress);
  const auto tBuild = Clock::now();
  watch.begin("building the scene");
  World world(scene, o.threads, submission);
  watch.end();
  const double buildMs = std::chrono::duration<double, std::milli>(Clock::now() - tBuild).count();
  const uint32_t frames = o.frames ? o.frames : scene.settings.frames;

  Series total, broad, contacts, solver, integrate, rays, edits;
  uint64_t pairs = 0, contactCount = 0, boxTests = 0, reused = 0, rayCount = 0, rayHits = 0, rayBoxTests = 0, terrainContacts = 0;
  uint64_t removed = 0, placed = 0, editSkipped = 0, splits = 0, debris = 0;
  Series splitTimes;
  uint64_t voxelsCarved = 0, terrainParts = 0, debrisVoxels = 0, voxelsSearched = 0;
  Series terrainEditTimes;  // frames that carved
  const bool gridEdits = std::any_of(scene.edits.begin(), scene.edits.end(), [](const EditLoadDescription& e) { return !e.grid.empty(); });
  const bool terrainEdits = std::any_of(scene.edits.begin(), scene.edits.end(), [](const EditLoadDescription& e) { return !e.terrain.empty(); });
  double editMsTotal = 0, editLoadMsTotal = 0;
  uint32_t floating = 0, largestIsland = 0, splitIslands = 0;
  std::ofstream csv;
  if (!o.csvPath.empty()) {
    csv.open(o.csvPath);
    if (!csv) throw std::runtime_error("cannot write " + o.csvPath);
    csv << "frame,total_ms,broadphase_ms,contacts_ms,solver_ms,integrate_ms,rays_ms,pairs,contacts,box_tests,ray_hits,"
           "bodies_inside_solid,transform_update_ms,submission_ms,commit_ms,render_wait_ms,render_busy_ms,moved_bodies,records,"
           "edit_ms,bricks_removed,bricks_placed\n";
  }
  double work = 0, span = 0;
  float deepest = 0, endDeepest = 0;  // deepest contact over the run and in the last frame
  std::vector<Vec3d> settled;  // positions at --drift-after
  ContainmentTracker containment(world);  // updated after each step, outside its timing
  SceneCheckTracker checks(world);        // the scene's own checks, likewise
  RenderFigures render;
  std::unique_ptr<RecordingWriter> recording;
  if (!o.recordPath.empty()) {
    RecordingOptions ro;
    ro.contacts = o.recordContacts;
    ro.gzip = o.recordGzip;
    ro.maxGridBricks = o.recordBricks;
    ro.nodeLevels = o.recordDepth;
    recording = std::make_unique<RecordingWriter>(world, o.recordPath, ro, o.threads);
  }
  const auto tRun = Clock::now();
  double simulationMs = 0;  // the steps' own time; the rest of the run is bookkeeping
  uint64_t containmentQueries = 0;  // bodies the containment checks queried (what its shortcuts left)
  for (uint32_t f = 0; f < frames; ++f) {
    if (o.driftAfter && f == o.driftAfter) settled = world.bodies().position;
    watch.begin("frame", f + 1, frames);
    world.step();
    watch.end();
    const StepStats& s = world.lastStats();
    simulationMs += s.totalMs;
    containment.update();
    containmentQueries += containment.lastQueried();
    checks.update();
    if (recording) recording->frame(world, containment.report());
    endDeepest = deepestContact(world);
    deepest = std::max(deepest, endDeepest);
    total.v.push_back(s.totalMs);
    broad.v.push_back(s.broadphaseMs);
    contacts.v.push_back(s.contactsMs);
    solver.v.push_back(s.solverMs);
    integrate.v.push_back(s.integrateMs);
    rays.v.push_back(s.raysMs);
    edits.v.push_back(s.editMs);
    editMsTotal += s.editMs;
    editLoadMsTotal += s.editLoadMs;
    removed += s.bricksRemoved;
    placed += s.bricksPlaced;
    editSkipped += s.editsSkipped;
    splits += s.splits;
    debris += s.debrisBricks;
    splitTimes.v.push_back(s.splitMs);
    voxelsCarved += s.voxelsCarved;
    terrainParts += s.terrainParts;
    debrisVoxels += s.debrisVoxels;
    voxelsSearched += s.voxelsSearched;
    if (s.voxelsCarved) terrainEditTimes.v.push_back(s.terrainEditMs);
    if (world.render()) render.add(s);
    rayCount += s.rays;
    rayHits += s.rayHits;
    rayBoxTests += s.rayBoxTests;
    terrainContacts += s.terrainContacts;
    floating = s.floating;
    largestIsland = std::max(largestIsland, s.largestIsland);
    splitIslands += s.splitIslands;
    pairs += s.pairs;
    contactCount += s.contacts;
    boxTests += s.boxTests;
    reused += s.pairsReused;
    if (csv) csv << f << "," << s.totalMs << "," << s.broadphaseMs << "," << s.contactsMs << "," << s.solverMs << ","
                 << s.integrateMs << "," << s.raysMs << "," << s.pairs << "," << s.contacts << "," << s.boxTests << "," << s.rayHits
                 << "," << containment.report().count() << "," << s.render.updateMs << "," << s.render.submissionMs << ","
                 << s.render.commitMs << "," << s.render.waitMs << "," << s.render.renderBusyMs << "," << s.render.movedBodies << ","
                 << s.render.primitives + s.render.lights << "," << s.editMs << "," << s.bricksRemoved << "," << s.bricksPlaced
                 << "\n";
    if (o.progress && !o.json && frames >= 100 && (f + 1) % (frames / 10) == 0)
      std::fprintf(stderr, "  frame %u/%u  %.2f ms\n", f + 1, frames, s.totalMs);
  }
  const double runS = std::chrono::duration<double>(Clock::now() - tRun).count();
  if (world.render()) render.finish(world);
  // Work and span over the whole run (stages are sequential, each stage's work in one zone here).
  const WorkSpanTotals runWorkSpan = world.profiler().workSpanTotals(frames);
  work += runWorkSpan.workMs;
  span += runWorkSpan.spanMs;
  if (!o.tracePath.empty()) world.profiler().writeChromeTrace(o.tracePath);
  // `--submission all` adds each mode's render times to the recording before it is closed.
  const auto recordMode = [&](const char* mode, const RenderFigures& f) {
    if (recording) recording->submissionMode(mode, f.update.v, f.submission.v, f.commit.v, f.wait.v);
  };
  // Bookkeeping: everything the run did besides stepping (containment checks, deepest contact,
  // counters, CSV, work/span, the trace), against the simulation's own time.
  const double bookkeepingMs = std::chrono::duration<double, std::milli>(Clock::now() - tRun).count() - simulationMs;

  // Where the dynamic bodies ended up: at rest, still moving, and the lowest one (a body far
  // below everything would have fallen through).
  uint32_t resting = 0, moving = 0;
  double lowest = std::numeric_limits<double>::infinity();
  const BodyStore& bodies = world.bodies();
  for (uint32_t i = 0; i < bodies.size(); ++i) {
    if (bodies.motion[i] != MotionType::Dynamic) continue;
    (bodies.linearVelocity[i].norm() < 0.05f && bodies.angularVelocity[i].norm() < 0.1f ? resting : moving)++;
    lowest = std::min(lowest, bodies.position[i].z());
  }
  // Bodies that ended inside solid (in a brick, in a solid voxel, or under a surface they passed).
  const ContainmentReport& inside = containment.report();
  double drift = 0;
  for (uint32_t i = 0; i < settled.size(); ++i)
    if (bodies.motion[i] == MotionType::Dynamic) drift = std::max(drift, (bodies.position[i] - settled[i]).norm());
  auto stage = [](const Series& s) { return nlohmann::json{{"median_ms", s.quantile(0.5)}, {"p95_ms", s.quantile(0.95)}, {"max_ms", s.max()}}; };
  if (o.json) {
    nlohmann::json j{{"scene", scene.name},
                     {"file", path},
                     {"threads", o.threads},
                     {"frames", frames},
                     {"bodies", world.bodies().size()},
                     {"bricks", world.brickCount()},
                     {"build_ms", buildMs},
                     {"frame", stage(total)},
                     {"broadphase", stage(broad)},
                     {"contacts", stage(contacts)},
                     {"solver", stage(solver)},
                     {"integrate", stage(integrate)},
                     {"pairs_per_frame", double(pairs) / frames},
                     {"pairs_reused_per_frame", double(reused) / frames},
                     {"contacts_per_frame", double(contactCount) / frames},
                     {"box_tests_per_frame", double(boxTests) / frames},
                     {"largest_island_contacts", largestIsland},
                     {"split_islands_per_frame", double(splitIslands) / frames},
                     {"peak_resident_mib", peakResidentMiB()},
                     {"dynamic_resting", resting},
                     {"dynamic_asleep", world.sleepingCount()},
                     {"dynamic_moving", moving},
                     {"lowest_dynamic_z", std::isfinite(lowest) ? lowest : 0.0},
                     {"bodies_inside_solid", inside.count()},
                     {"max_penetration_m", deepest},
                     {"end_penetration_m", endDeepest},
                     {"bodies_started_in_solid", world.startedInSolid()},
                     {"bodies_being_pushed_out", world.depenetratingCount()},
                     {"state_hash", world.stateHash()},
                     {"simulation_ms", simulationMs},
                     {"bookkeeping_ms", bookkeepingMs},
                     {"bookkeeping_share", bookkeepingMs / std::max(simulationMs, 1e-9)},
                     {"containment_queries_per_frame", double(containmentQueries) / std::max(frames, 1u)}};
    if (inside.count()) j["inside_solid"] = insideSolidList(inside, bodies.position);
    if (checks.any()) j["checks"] = checksJson(checks);
    if (recording) j["recording"] = {{"file", o.recordPath}, {"frames", recording->frames()}, {"bytes_uncompressed", recording->bytes()}};
    if (!settled.empty()) j["drift_after_frame"] = {{"frame", o.driftAfter}, {"max_displacement_m", drift}};
    if (!scene.terrains.empty()) {
      j["terrain_contacts_per_frame"] = double(terrainContacts) / frames;
      j["dynamic_floating"] = floating;
    }
    if (terrainEdits) {
      j["terrain_edits"] = {{"voxels_carved", voxelsCarved}, {"regions_broken_free", terrainParts}, {"debris_voxels", debrisVoxels},
                            {"voxels_searched", voxelsSearched}, {"carve_frames", terrainEditTimes.v.size()},
                            {"median_ms", terrainEditTimes.quantile(0.5)}, {"max_ms", terrainEditTimes.max()}};
    }
    if (gridEdits) {
      j["edits"] = stage(edits);
      j["bricks_removed_per_frame"] = double(removed) / frames;
      j["bricks_placed_per_frame"] = double(placed) / frames;
      j["edits_skipped_per_frame"] = double(editSkipped) / frames;
      j["edit_us_per_brick"] = removed + placed ? 1e3 * editMsTotal / double(removed + placed) : 0.0;
      j["edit_load_choosing_ms_per_frame"] = editLoadMsTotal / frames;
      j["splits"] = splits;
      j["debris_bricks"] = debris;
      j["split"] = stage(splitTimes);
    }
    if (rayCount) {
      j["rays"] = stage(rays);
      j["rays_per_frame"] = double(rayCount) / frames;
      j["ray_hit_share"] = double(rayHits) / double(rayCount);
      j["ray_box_tests_per_ray"] = double(rayBoxTests) / double(rayCount);
    }
    bool modesAgree = true;
    if (world.render()) {
      j["render"] = render.json(world);
      if (submissionName == "all")
        modesAgree = compareSubmissionModes(scene, o.threads, frames, world, render, true, j["submission_modes"], recordMode);
    }
    if (recording) recording->finish();
    for (BulletSetup setup : setups) {
      nlohmann::json b;
      const double bulletMedian = runBullet(scene, o.threads, setup, o.bulletChunk, kinematicGridsFromName(o.bulletKinematic), frames, true, b);
      const std::string key = setup == BulletSetup::Expert ? "bullet" : "bullet_naive";
      j[key] = b;
      j[key + "_over_brickworld_median"] = bulletMedian / std::max(total.quantile(0.5), 1e-9);
    }
    std::cout << j.dump(2) << "\n";
    return !modesAgree ? 3 : checks.pass() ? 0 : 4;
  }
  std::printf("scene %s (%s): %u bodies, %llu bricks, built in %.0f ms; %u frames on %d thread(s) in %.2f s\n", scene.name.c_str(),
              path.c_str(), world.bodies().size(), (unsigned long long)world.brickCount(), buildMs, frames, o.threads, runS);
  std::printf("  %-11s %9s %9s %9s\n", "stage", "median", "p95", "max");
  for (auto [name, s] : {std::pair<const char*, const Series*>{"frame", &total}, {"broadphase", &broad}, {"contacts", &contacts},
                         {"solver", &solver}, {"integrate", &integrate}, {"rays", &rays}, {"edits", &edits}}) {
    if (s == &rays && rayCount == 0) continue;
    if (s == &edits && !gridEdits) continue;
    std::printf("  %-11s %7.3f ms %7.3f ms %7.3f ms\n", name, s->quantile(0.5), s->quantile(0.95), s->max());
  }
  std::printf("  simulation %.0f ms; bookkeeping (containment, counters, CSV, work/span, trace) %.0f ms = %.1f%% of it\n",
              simulationMs, bookkeepingMs, 100.0 * bookkeepingMs / std::max(simulationMs, 1e-9));
  std::printf("  per frame: %.0f pairs (%.0f reused from the pair cache), %.0f contacts, %.0f box tests\n", double(pairs) / frames,
              double(reused) / frames, double(contactCount) / frames, double(boxTests) / frames);
  std::printf("  islands: largest %u contacts; %.1f per frame split by colour over the threads\n", largestIsland,
              double(splitIslands) / frames);
  if (rayCount)
    std::printf("  rays: %.0f per frame, %.1f%% hit, %.0f box tests per ray\n", double(rayCount) / frames,
                100.0 * double(rayHits) / double(rayCount), double(rayBoxTests) / double(rayCount));
  if (gridEdits)
    std::printf("  edits: %.0f bricks removed and %.0f placed per frame (%.1f skipped), %.2f us per brick edited (index, mass, "
                "wakes, caches); the load's own choosing %.3f ms per frame, outside the edit times\n",
                double(removed) / frames, double(placed) / frames, double(editSkipped) / frames,
                removed + placed ? 1e3 * editMsTotal / double(removed + placed) : 0.0, editLoadMsTotal / frames);
  if (terrainEdits)
    std::printf("  terrain edits: %llu voxels carved on %zu frames, %llu regions broke free as bodies, %llu debris voxels gone; the "
                "cut-off search visited %llu voxels; carve, search and bodies %.3f ms median, %.3f ms max a carving frame\n",
                (unsigned long long)voxelsCarved, terrainEditTimes.v.size(), (unsigned long long)terrainParts,
                (unsigned long long)debrisVoxels, (unsigned long long)voxelsSearched, terrainEditTimes.quantile(0.5), terrainEditTimes.max());
  if (gridEdits && (splits || debris || splitTimes.max() > 0))
    std::printf("  splits: %llu parts became bodies, %llu debris bricks gone; connectivity and splitting %.3f ms median, %.3f ms max a frame\n",
                (unsigned long long)splits, (unsigned long long)debris, splitTimes.quantile(0.5), splitTimes.max());
  if (!scene.terrains.empty())
    std::printf("  terrain: %.0f contacts per frame, %u bodies in water at the end\n", double(terrainContacts) / frames, floating);
  std::printf("  dynamic bodies at the end: %u resting (%u asleep), %u moving, lowest at z = %.2f\n", resting,
              world.sleepingCount(), moving, std::isfinite(lowest) ? lowest : 0.0);
  std::printf("  bodies inside solid at the end: %u (%u started inside solid and were pushed out, %u still on their way)\n",
              inside.count(), world.startedInSolid(), world.depenetratingCount());
  std::printf("  deepest contact %.1f mm over the run, %.1f mm in the last frame\n", deepest * 1e3, endDeepest * 1e3);
  for (uint32_t k = 0; k < inside.count() && k < 5; ++k) {
    const Vec3d& p = bodies.position[inside.bodies[k]];
    std::printf("    body %u at (%.2f, %.2f, %.2f): %s\n", inside.bodies[k], p.x(), p.y(), p.z(), insideSolidName(inside.reasons[k]));
  }
  printChecks(checks);
  if (!settled.empty())
    std::printf("  drift: largest displacement of a dynamic body from frame %u to the end %.3f mm\n", o.driftAfter, drift * 1e3);
  if (world.render()) render.print(world);
  std::printf("  peak memory %.0f MiB; state hash %016llx\n", peakResidentMiB(), (unsigned long long)world.stateHash());
  std::printf("  work %.1f ms, span %.1f ms over the run\n", work, span);
  if (!o.csvPath.empty()) std::printf("  per-frame CSV: %s\n", o.csvPath.c_str());
  if (!o.tracePath.empty()) std::printf("  Chrome trace: %s (open in Perfetto)\n", o.tracePath.c_str());
  if (recording)
    std::printf("  recording: %s (%u frames, %.1f MB%s; brickworld view %s -o PAGE.html)\n", o.recordPath.c_str(), recording->frames(),
                recording->bytes() / 1e6, o.recordGzip ? " before compression" : "", o.recordPath.c_str());
  bool modesAgree = true;
  if (world.render() && submissionName == "all") {
    nlohmann::json unused;
    modesAgree = compareSubmissionModes(scene, o.threads, frames, world, render, false, unused, recordMode);
  }
  if (recording) recording->finish();
  for (BulletSetup setup : setups) {
    nlohmann::json b;
    const double bulletMedian = runBullet(scene, o.threads, setup, o.bulletChunk, kinematicGridsFromName(o.bulletKinematic), frames, false, b);
    std::printf("%s / brickworld median frame time: %.1fx\n", setup == BulletSetup::Expert ? "bullet" : "bullet-naive",
                bulletMedian / std::max(total.quantile(0.5), 1e-9));
  }
  return !modesAgree ? 3 : checks.pass() ? 0 : 4;
}

}  // namespace bw::cli
