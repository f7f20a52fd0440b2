// `brickworld tradeoff SCENE`: what each speed-for-accuracy knob buys and costs. A reference run
// at the most accurate settings, then one run per value of each knob (the others at the scene's
// own settings), each measured for cost (step time, box tests) and error against the reference
// (errors defined in README "Speed vs accuracy"). Writes a CSV (and JSON with --json); the PNG
// plots come from profiles/plot_tradeoff.py.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/command_registry.h"
#include "cli/output_check.h"
#include "cli/scene_run.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw::cli {
namespace {

// Contacts closer than this (and with normals within ~25 degrees) count as the same contact.
constexpr double kMatchDistance = 0.05;
constexpr float kMatchNormalDot = 0.9f;
// Probe the LOD's contacts against LOD off every this many frames.
constexpr uint32_t kProbeEvery = 10;

struct Knob {
  std::string name;
  std::vector<double> values;
  void (*apply)(SceneSettings&, double);
};

const std::vector<Knob>& knobs() {
  static const std::vector<Knob> list = {
      {"lod_fraction", {0, 1.0 / 32, 1.0 / 16, 1.0 / 8, 1.0 / 4, 1.0 / 2}, [](SceneSettings& s, double v) { s.lodFraction = float(v); }},
      {"approximation_depth", {1, 2, 3, 4, 5}, [](SceneSettings& s, double v) { s.approximationDepth = int(v); }},
      {"solver_iterations", {2, 4, 8, 16, 32}, [](SceneSettings& s, double v) { s.solverIterations = int(v); }},
      {"substeps", {1, 2, 4}, [](SceneSettings& s, double v) { s.substeps = int(v); }},
      {"manifold_size", {1, 2, 4, 8}, [](SceneSettings& s, double v) { s.manifoldSize = int(v); }},
      // 0 convex, 1 two-way, 2 auto (GridPairMode)
      {"grid_pairs", {0, 1, 2}, [](SceneSettings& s, double v) { s.gridPairs = GridPairMode(int(v)); }},
      {"pair_cache_tolerance", {0, 1e-4, 1e-3, 1e-2},
       [](SceneSettings& s, double v) {
         s.reuseTranslation = v;
         s.reuseRotation = float(v);
       }},
  };
  return list;
}

// The most accurate settings: no LOD, deep approximations, many iterations and substeps, big
// manifolds, no pair cache, grids against grids brick against brick. Sleeping stays as the scene says (it changes what is simulated).
SceneSettings referenceSettings(SceneSettings s) {
  s.lodFraction = 0;
  s.approximationDepth = 5;
  s.solverIterations = 32;
  s.substeps = 4;
  s.manifoldSize = 8;
  s.reuseTranslation = 0;
  s.reuseRotation = 0;
  s.gridPairs = GridPairMode::TwoWay;
  return s;
}

struct RunResult {
  std::string knob;
  double value = 0;
  double medianMs = 0, p95Ms = 0, boxTestsPerFrame = 0, contactsPerFrame = 0;
  double penetrationMax = 0, penetrationMean = 0;
  double energyGain = 0;  // largest rise of the dynamic bodies' energy over an earlier minimum (J)
  double poseMax = 0, poseMean = 0, angleMaxDeg = 0;
  double missedShare = -1, addedShare = -1;  // LOD only: vs LOD off at the same states
  double hullVolumeError = -1;               // approximation depth only
  std::vector<Vec3d> finalPositions;
  std::vector<Quatf> finalRotations;
};

// Contacts of `test` with no match in `ref`, summed over pairs.
uint64_t unmatched(const std::vector<std::vector<Contact>>& test, const std::vector<std::vector<Contact>>& ref, size_t pairs) {
  uint64_t n = 0;
  for (size_t k = 0; k < pairs; ++k) {
    for (const Contact& c : test[k]) {
      const bool found = std::any_of(ref[k].begin(), ref[k].end(), [&](const Contact& r) {
        return (r.position - c.position).norm() < kMatchDistance && r.normal.dot(c.normal) > kMatchNormalDot;
      });
      n += found ? 0 : 1;
    }
  }
  return n;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5))];
}

// Largest relative error of a grid's convex approximation volume against its bricks' volume,
// over the grids that get approximated (grid vs grid uses the smaller grid's approximation, so
// every grid but the scene's largest; density 1 makes mass the volume). -1: no such grid.
double hullVolumeError(World& world, const SceneDescription& scene, int depth) {
  const uint32_t grids = uint32_t(scene.grids.size());
  if (grids < 2) return -1;
  uint64_t largest = 0;
  for (uint32_t g = 0; g < grids; ++g) largest = std::max<uint64_t>(largest, world.grid(g).brickCount());
  double worst = 0;
  for (uint32_t g = 0; g < grids; ++g) {
    BrickGrid& grid = world.editGrid(g);
    if (grid.brickCount() == largest) continue;
    const double truth = grid.massProperties().mass;
    if (truth <= 0) continue;
    worst = std::max(worst, std::abs(grid.convexApproximation(depth).hullVolume - truth) / truth);
  }
  return worst;
}

RunResult runOnce(const SceneDescription& scene, int threads, uint32_t frames, const RunResult* reference, bool probeLod) {
  World world(scene, threads);
  RunResult r;
  std::vector<double> times;
  uint64_t boxTests = 0, contacts = 0, penetrating = 0, probes = 0, refContacts = 0, missed = 0, added = 0;
  double depthSum = 0;
  double lowestEnergy = world.energy();
  for (uint32_t f = 0; f < frames; ++f) {
    world.step();
    const StepStats& s = world.lastStats();
    times.push_back(s.totalMs);
    boxTests += s.boxTests;
    contacts += s.contacts;
    for (uint32_t k = 0; k < world.pairs().size(); ++k)
      for (const Contact& c : world.pairContacts(k))
        if (c.depth > 0) {
          r.penetrationMax = std::max(r.penetrationMax, double(c.depth));
          depthSum += c.depth;
          ++penetrating;
        }
    // Collisions and friction only take energy out; there are no motors, so a rise above an
    // earlier low is energy the solver put in (kinematic bodies pushing others excepted).
    const double e = world.energy();
    lowestEnergy = std::min(lowestEnergy, e);
    r.energyGain = std::max(r.energyGain, e - lowestEnergy);
    if (probeLod && f % kProbeEvery == kProbeEvery - 1) {
      const size_t pairs = world.pairs().size();
      const SceneSettings& st = scene.settings;
      const std::vector<std::vector<Contact>> off = world.probeContacts(0.f, st.approximationDepth, st.manifoldSize);
      const std::vector<std::vector<Contact>>& lod = world.probeContacts(st.lodFraction, st.approximationDepth, st.manifoldSize);
      for (size_t k = 0; k < pairs; ++k) refContacts += off[k].size();
      missed += unmatched(off, lod, pairs);
      added += unmatched(lod, off, pairs);
      ++probes;
    }
  }
  r.medianMs = quantile(times, 0.5);
  r.p95Ms = quantile(times, 0.95);
  r.boxTestsPerFrame = double(boxTests) / frames;
  r.contactsPerFrame = double(contacts) / frames;
  r.penetrationMean = penetrating ? depthSum / double(penetrating) : 0;
  if (probes) {
    r.missedShare = refContacts ? double(missed) / double(refContacts) : 0;
    r.addedShare = refContacts ? double(added) / double(refContacts) : 0;
  }
  const BodyStore& b = world.bodies();
  for (uint32_t i = 0; i < b.size(); ++i) {
    r.finalPositions.push_back(b.position[i]);
    r.finalRotations.push_back(b.rotation[i]);
  }
  if (reference) {
    double sum = 0;
    uint32_t dynamic = 0;
    for (uint32_t i = 0; i < b.size(); ++i) {
      if (b.motion[i] != MotionType::Dynamic) continue;
      const double d = (b.position[i] - reference->finalPositions[i]).norm();
      r.poseMax = std::max(r.poseMax, d);
      sum += d;
      ++dynamic;
      r.angleMaxDeg = std::max(r.angleMaxDeg, double(b.rotation[i].angularDistance(reference->finalRotations[i])) * 57.29578);
    }
    r.poseMean = dynamic ? sum / dynamic : 0;
  }
  return r;
}

int runTradeoff(const std::string& sceneName, uint32_t framesOption, int threads, const std::string& only, const std::string& sleeping,
                const std::string& csvPath, bool json) {
  SceneDescription scene = loadScene(resolveScenePath(sceneName));
  if (!sleeping.empty()) scene.settings.sleeping = sleeping == "on";
  const std::string out = csvPath.empty() ? "tradeoff_" + scene.name + ".csv" : csvPath;
  requireWritable(out, "--csv");
  const uint32_t frames = framesOption ? framesOption : scene.settings.frames;
  SceneDescription refScene = scene;
  refScene.settings = referenceSettings(scene.settings);
  if (!json) std::fprintf(stderr, "tradeoff %s: reference run (%u frames at the most accurate settings)...\n", scene.name.c_str(), frames);
  RunResult reference = runOnce(refScene, threads, frames, nullptr, false);
  reference.knob = "reference";

  std::vector<RunResult> rows;
  for (const Knob& knob : knobs()) {
    if (!only.empty() && only != knob.name) continue;
    for (double v : knob.values) {
      SceneDescription s = scene;
      knob.apply(s.settings, v);
      if (!json) std::fprintf(stderr, "  %s = %g\n", knob.name.c_str(), v);
      const bool lod = knob.name == "lod_fraction" && v > 0;
      RunResult r = runOnce(s, threads, frames, &reference, lod);
      if (lod || (knob.name == "lod_fraction" && v == 0)) {
        if (!lod) r.missedShare = r.addedShare = 0;
      }
      if (knob.name == "approximation_depth") {
        World w(s, 1);
        r.hullVolumeError = hullVolumeError(w, s, int(v));
      }
      r.knob = knob.name;
      r.value = v;
      rows.push_back(std::move(r));
    }
  }
  if (!only.empty() && rows.empty()) throw std::invalid_argument("--knob: no knob named '" + only + "'");

  std::ofstream csv(out);
  if (!csv) throw std::runtime_error("cannot write " + out);
  csv << "knob,value,median_ms,p95_ms,box_tests_per_frame,contacts_per_frame,penetration_max,penetration_mean,energy_gain,"
         "pose_divergence_max,pose_divergence_mean,angle_divergence_max_deg,contacts_missed_share,contacts_added_share,"
         "hull_volume_error\n";
  auto write = [&](const RunResult& r) {
    csv << r.knob << "," << r.value << "," << r.medianMs << "," << r.p95Ms << "," << r.boxTestsPerFrame << "," << r.contactsPerFrame << ","
        << r.penetrationMax << "," << r.penetrationMean << "," << r.energyGain << "," << r.poseMax << "," << r.poseMean << ","
        << r.angleMaxDeg << "," << r.missedShare << "," << r.addedShare << "," << r.hullVolumeError << "\n";
  };
  write(reference);
  for (const RunResult& r : rows) write(r);

  if (json) {
    nlohmann::json j{{"scene", scene.name}, {"frames", frames}, {"threads", threads}, {"csv", out}};
    auto row = [](const RunResult& r) {
      return nlohmann::json{{"knob", r.knob}, {"value", r.value}, {"median_ms", r.medianMs}, {"p95_ms", r.p95Ms},
                            {"box_tests_per_frame", r.boxTestsPerFrame}, {"penetration_max", r.penetrationMax},
                            {"penetration_mean", r.penetrationMean}, {"energy_gain", r.energyGain},
                            {"pose_divergence_max", r.poseMax}, {"pose_divergence_mean", r.poseMean},
                            {"contacts_missed_share", r.missedShare}, {"contacts_added_share", r.addedShare},
                            {"hull_volume_error", r.hullVolumeError}};
    };
    j["reference"] = row(reference);
    for (const RunResult& r : rows) j["runs"].push_back(row(r));
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::printf("tradeoff %s: %u frames on %d thread(s); reference %.3f ms median; CSV: %s\n", scene.name.c_str(), frames, threads,
              reference.medianMs, out.c_str());
  std::printf("  %-21s %7s %8s %8s %10s %8s %8s %9s %9s %7s %7s %7s\n", "knob", "value", "med ms", "p95 ms", "box tests", "pen max",
              "pen mean", "E gain J", "pose mean", "miss", "add", "hull");
  auto pct = [](double v) { return v < 0 ? std::string("-") : std::to_string(int(std::lround(v * 100))) + "%"; };
  for (const RunResult& r : rows)
    std::printf("  %-21s %7g %8.3f %8.3f %10.0f %8.4f %8.4f %9.3g %9.4f %7s %7s %7s\n", r.knob.c_str(), r.value, r.medianMs, r.p95Ms,
                r.boxTestsPerFrame, r.penetrationMax, r.penetrationMean, r.energyGain, r.poseMean, pct(r.missedShare).c_str(),
                pct(r.addedShare).c_str(), pct(r.hullVolumeError).c_str());
  std::printf("  plots: python3 %s/profiles/plot_tradeoff.py %s -o %s\n", BW_SOURCE_DIR, out.c_str(),
              std::filesystem::path(out).replace_extension(".png").string().c_str());
  return 0;
}

CommandRegistration reg{"tradeoff", "Cost against error for each speed/accuracy knob, against a most-accurate reference run",
                        [](CLI::App& cmd) {
  auto scene = std::make_shared<std::string>("crates_on_grid");
  auto frames = std::make_shared<uint32_t>(0);
  auto threads = std::make_shared<int>(1);
  auto knob = std::make_shared<std::string>();
  auto csv = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto sleeping = std::make_shared<std::string>();
  cmd.add_option("--sleeping", *sleeping, "on/off overrides the scene's sleeping setting")->check(CLI::IsMember({"on", "off"}));
  cmd.add_option("scene", *scene, "scene file or shipped scene name (default crates_on_grid)");
  cmd.add_option("--frames", *frames, "frames per run (default: the scene's)")->check(CLI::Range(1u, 10'000'000u));
  cmd.add_option("--threads", *threads, "threads (default 1)")->check(CLI::Range(1, 1024));
  cmd.add_option("--knob", *knob, "only this knob (lod_fraction, approximation_depth, solver_iterations, substeps, manifold_size, "
                                  "grid_pairs (0 convex, 1 two-way, 2 auto), pair_cache_tolerance)");
  cmd.add_option("--csv", *csv, "CSV to write (default tradeoff_<scene>.csv)");
  cmd.add_flag("--json", *json, "print one JSON object");
  return [=] { return runTradeoff(*scene, *frames, *threads, *knob, *sleeping, *csv, *json); };
}};

}  // namespace
}  // namespace bw::cli
