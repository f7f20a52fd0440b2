// The world's step: the substeps' stages in order (broadphase, contacts, solve, integrate,
// relax, sleep), then the ray load. Each stage lives in its own file; this one orchestrates.
#include "world/world.h"

#include <algorithm>
#include <atomic>
#include <chrono>

#include "collision/core/argument_checks.h"
#include "collision/core/hash.h"
#include "world/body_mass.h"
#include "world/scene_file.h"
#include "world/scene_validation.h"
#include "world/world_tuning.h"

namespace bw {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

}  // namespace

World::World(const SceneDescription& scene, int threads, SubmissionMode submission)
    : scene_((validateScene(scene), scene)), jobs_(threads) {
  for (const GridDescription& g : scene_.grids) buildGrid(g);
  for (const TerrainDescription& t : scene_.terrains) buildTerrain(t);
  for (const SpawnerDescription& s : scene_.spawners) spawn(s);
  std::vector<EditLoadDescription> gridEdits;
  std::vector<uint32_t> editGrids, editTerrains;
  for (const EditLoadDescription& e : scene_.edits) {
    uint32_t terrain = 0;
    while (terrain < scene_.terrains.size() && scene_.terrains[terrain].name != e.terrain) ++terrain;
    editTerrains.push_back(terrain);
    if (!e.grid.empty()) {
      gridEdits.push_back(e);
      editGrids.push_back(uint32_t(std::find(gridNames_.begin(), gridNames_.end(), e.grid) - gridNames_.begin()));
    }
  }
  editLoad_ = EditLoad(std::move(gridEdits), std::move(editGrids));
  std::vector<int32_t> anchors;
  for (const TerrainBreak& b : terrainBreaks_) anchors.push_back(b.anchorZ);
  carveLoad_ = TerrainCarveLoad(scene_.edits, editTerrains, std::move(anchors));
  gridBodies_.assign(grids_.size(), {});
  for (uint32_t i = 0; i < bodies_.size(); ++i)
    if (bodies_.shape[i].isGrid()) gridBodies_[bodies_.shape[i].grid].push_back(i);
  for (uint32_t i = 0; i < bodies_.size(); ++i)
    if (bodies_.shape[i].isGrid() || bodies_.shape[i].isTerrain()) solidBodies_.push_back(i);
  nearSolid_.assign(bodies_.size(), 1);  // no step yet: containment checks every body
  sleep_.reset(bodies_.size());
  resolveStartsInSolid();
  if (scene_.attachments.enabled)
    render_ = std::make_unique<WorldRender>(buildAttachments(), submission, bodies_.size(), scene_.attachments.batchPrimitives,
                                            scene_.attachments.batchLights, profiler_);
}

const RenderScene& World::renderScene() {
  if (!render_) throw InvalidInput("World::renderScene: scene '" + scene_.name + "' declares no attachments (no render thread)");
  render_->finish();
  return render_->scene();
}

const BrickGrid& World::grid(uint32_t index) const {
  if (index >= grids_.size())
    throw InvalidInput("World::grid: index is " + std::to_string(index) + ", the world has " + std::to_string(grids_.size()) + " grids");
  return *grids_[index];
}

const std::string& World::gridName(uint32_t index) const {
  if (index >= grids_.size())
    throw InvalidInput("World::gridName: index is " + std::to_string(index) + ", the world has " + std::to_string(grids_.size()) + " grids");
  return gridNames_[index];
}

uint32_t World::gridBody(const std::string& name) const {
  const auto it = std::find(gridNames_.begin(), gridNames_.end(), name);
  if (it != gridNames_.end()) {
    const uint32_t index = uint32_t(it - gridNames_.begin());
    for (uint32_t b = 0; b < bodies_.size(); ++b)
      if (bodies_.shape[b].isGrid() && bodies_.shape[b].grid == index) return b;
  }
  throw SceneError(scene_.source + ": no grid body named '" + name + "'");
}

const Terrain& World::terrain(uint32_t index) const {
  if (index >= terrains_.size())
    throw InvalidInput("World::terrain: index is " + std::to_string(index) + ", the world has " + std::to_string(terrains_.size()) +
                       " terrains");
  return *terrains_[index];
}

BrickGrid& World::editGrid(uint32_t index) {
  if (index >= grids_.size())
    throw InvalidInput("World::editGrid: index is " + std::to_string(index) + ", the world has " + std::to_string(grids_.size()) +
                       " grids");
  editedGrids_.push_back(index);
  wholeGridEdits_.push_back(index);  // where it is edited is not known: everything on it wakes
  if (renderChunks_) renderChunks_->gridChanged(index);
  if (links_[index]) linksStale_[index] = 1;
  if (recordingEdits_) betweenSteps_.wholeGrids.push_back(index);
  return *grids_[index];
}

World::RemovalResult World::removeBricks(uint32_t index, std::span<const uint32_t> bricks) {
  const auto t = Clock::now();
  if (index >= grids_.size())
    throw InvalidInput("World::removeBricks: index is " + std::to_string(index) + ", the world has " + std::to_string(grids_.size()) +
                       " grids");
  BrickGrid& grid = *grids_[index];
  for (uint32_t id : bricks)
    if (!grid.hasBrick(id))
      throw InvalidInput("World::removeBricks: brick " + std::to_string(id) + " is not in grid " + std::to_string(index) + " ('" +
                         gridNames_[index] + "')");
  refreshStaleLinks();
  // note: a brick listed twice is removed once (checked above while all were live).
  editLog_.clear();
  for (uint32_t id : bricks) {
    if (!grid.hasBrick(id)) continue;
    if (recordingEdits_) editLog_.bricks.push_back({index, id, false, grid.brick(id)});
    if (links_[index]) links_[index]->removing(id, splitSeeds_[index]);
    if (renderChunks_) renderChunks_->removing(index, grid.brick(id));
    grid.removeBrick(id);
  }
  editedGrids_.push_back(index);
  wholeGridEdits_.push_back(index);
  const StepStats kept = stats_;
  stats_.splits = stats_.debrisBricks = 0;
  stats_.partBodiesMs = 0;
  splitDetachedParts();
  RemovalResult r{stats_.splits, stats_.debrisBricks, 0.0, stats_.partBodiesMs};
  stats_ = kept;  // the last step's figures stay as they were
  if (recordingEdits_) {  // the next step's log starts with these
    betweenSteps_.bricks.insert(betweenSteps_.bricks.end(), editLog_.bricks.begin(), editLog_.bricks.end());
    betweenSteps_.splits.insert(betweenSteps_.splits.end(), editLog_.splits.begin(), editLog_.splits.end());
  }
  r.ms = msSince(t);
  return r;
}

uint64_t World::brickCount() const {
  uint64_t n = 0;
  for (const auto& g : grids_) n += g->brickCount();
  return n;
}

void World::integrate(float dt, int stage) {
  // Each body writes only its own pose: parallel, the same for any thread count. An asleep
  // body rides its carrier: it moves as the carrier does (the same velocity, no turn).
  jobs_.parallelFor(0, bodies_.size(), tuning::bodyGrain(bodies_.size()), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "integrate", stage);
    for (uint32_t i = begin; i < end; ++i) {
      if (bodies_.motion[i] == MotionType::Static || (sleep_.asleep(i) && !bodies_.translates(i))) continue;
      bodies_.position[i] += (bodies_.linearVelocity[i] * dt).cast<double>();
      const Vec3f w = bodies_.angularVelocity[i];
      const float angle = w.norm() * dt;
      if (angle > 0) bodies_.rotation[i] = (Quatf(Eigen::AngleAxisf(angle, w / w.norm())) * bodies_.rotation[i]).normalized();
    }
  });
}

void World::substep(float dt, int index) {
  // Stages of successive substeps run one after another: distinct stage ids for work/span.
  // Serial stages record one zone; parallel stages one zone per chunk (the jobs).
  const int stage = index * kStagesPerSubstep;
  stage_ = stage;
  auto t = Clock::now();
  computeBounds(scene_.settings.gravity.cast<float>() * dt, stage + 6);
  findPairs();
  stats_.broadphaseMs += msSince(t);
  t = Clock::now();
  {
    ProfileZone z(profiler_, "contacts (stage)");
    generateContacts(dt);
    terrainPairs(dt);
    pairCache_.update(pairs_, pairContacts_, pairFlipped_, pairReused_, bodies_, jobs_, profiler_, stage + kContactStepsStage + 2);
  }
  stats_.contactsMs += msSince(t);
  t = Clock::now();
  {
    solver_.prepare(bodies_, pairs_, pairContacts_, pairFlipped_, scene_.settings, dt, jobs_, profiler_, stage + 9,
                    stage + kContactStepsStage + 19);
    {
      ProfileZone z(profiler_, "wake touched", stage + 2);
      // A sleeping body touched by an awake one wakes up (its island rejoins the simulation).
      sleep_.wakeTouched(solver_.contacts(), bodies_, scene_.settings.sleeping);
    }
    islands_.build(solver_.contacts(), bodies_.motion, jobs_, profiler_, stage + 11);
    islands_.groupContacts(jobs_, profiler_, stage + kContactStepsStage + 8);
    ProfileZone z(profiler_, "solve (stage)");
    solver_.loadBodies(bodies_, jobs_, profiler_, stage + kContactStepsStage + 4);
    const SolveStats solved = solver_.solve(islands_, bodies_.motion, false, scene_.settings, jobs_, profiler_, stage);
    stats_.largestIsland = solved.largestIsland;
    stats_.splitIslands += solved.splitIslands;
    solver_.storeBodies(bodies_, jobs_, profiler_, stage + kContactStepsStage + 5);
  }
  stats_.solverMs += msSince(t);
  t = Clock::now();
  integrate(dt, stage + 4);
  stats_.integrateMs += msSince(t);
  t = Clock::now();
  {
    // Positions moved with the push-out; relaxing the velocities now removes it from what the
    // bodies carry into the next substep.
    ProfileZone z(profiler_, "relax (stage)");
    solver_.solve(islands_, bodies_.motion, true, scene_.settings, jobs_, profiler_, stage);
    solver_.storeBodies(bodies_, jobs_, profiler_, stage + kContactStepsStage + 6);
    solver_.keepImpulses(jobs_, profiler_, stage + kContactStepsStage + 14);
  }
  stats_.solverMs += msSince(t);
  if (scene_.settings.sleeping) sleep_.update(bodies_, islands_, dt, jobs_, profiler_, stage + 7);
  stats_.pairs += uint32_t(pairs_.size());
  stats_.contacts += uint32_t(solver_.contacts().size());
  // The pairs' counters and containment's filter, in parallel: integer sums per job.
  const uint32_t n = uint32_t(pairs_.size());
  const uint32_t grain = tuning::grainFor(n, tuning::kMinCounterGrain);
  pairCounters_.assign(JobSystem::chunkCount(0, n, grain), PairCounters{});
  jobs_.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "counters", stage + kContactStepsStage + 7);
    PairCounters& c = pairCounters_[begin / grain];
    for (uint32_t k = begin; k < end; ++k) {
      markNearSolid(k);
      if (pairReused_[k]) {
        ++c.reused;
        continue;
      }
      c.boxTests += pairStats_[k].index.boxTests;
      c.bricksTested += pairStats_[k].bricksTested;
    }
  });
  for (const PairCounters& c : pairCounters_) {
    stats_.pairsReused += c.reused;
    stats_.boxTests += c.boxTests;
    stats_.narrowphase += c.bricksTested;
  }
}

// Containment's filter (World::nearSolidLastStep): a body is near solid in this substep if a
// pair with a grid or terrain could have moved it into one. A grid pair that was collided and
// met no brick (nor a LOD box) within the body's bounds plus its closing distance, in a substep
// where the body had no contact at all (so nothing but gravity, already in its velocity,
// changed its motion), is not; every other pair with a solid body is (reused, skipped, terrain).
void World::markNearSolid(uint32_t k) {
  const BodyPair& p = pairs_[k];
  // note: pairs of one body may be marked by two jobs at once: relaxed atomic stores of 1.
  const auto mark = [&](uint32_t body) { std::atomic_ref<uint8_t>(nearSolid_[body]).store(1, std::memory_order_relaxed); };
  if (!pairContacts_[k].empty()) {
    mark(p.a);  // touched something: any impulse may push it anywhere
    mark(p.b);
    return;
  }
  const bool solidA = isSolid(p.a), solidB = isSolid(p.b);
  if (!solidA && !solidB) return;
  const bool collided = !pairReused_[k] && canCollide(p.a, p.b) && pairMoves(p.a, p.b) &&
                        !bodies_.shape[p.a].isTerrain() && !bodies_.shape[p.b].isTerrain();
  if (collided && pairStats_[k].bricksTested == 0 && pairStats_[k].lodBoxes == 0) return;
  if (solidA) mark(p.b);
  if (solidB) mark(p.a);
}

// After grid edits: bodies resting on an edited grid wake up (a removed brick must let them
// fall), and the pair cache forgets every pair with an edited grid (its cached contacts may
// belong to a brick that is gone).
void World::applyGridEdits() {
  if (editedGrids_.empty()) return;
  // Per grid: 0 unedited, 1 edited by the edit load only (which says where: only bodies near
  // the bricks it placed or removed wake and lose their cached contacts), 2 edited through
  // editGrid() or holding a dynamic body (everything paired with it wakes and forgets).
  std::vector<uint8_t> edited(grids_.size(), 0);
  for (uint32_t g : editedGrids_) edited[g] = 1;
  for (uint32_t g : wholeGridEdits_) edited[g] = 2;
  editedGrids_.clear();
  wholeGridEdits_.clear();
  for (uint32_t body = 0; body < bodies_.size(); ++body) {
    if (!bodies_.shape[body].isGrid() || !edited[bodies_.shape[body].grid] || bodies_.motion[body] != MotionType::Dynamic) continue;
    edited[bodies_.shape[body].grid] = 2;
    refreshGridBodyMass(body);
  }
  // The world boxes of the edit load's bricks, on every body holding their grid.
  std::vector<WorldAabb> boxes;
  std::vector<uint32_t> owners;
  // note: each holder's pose and rotation taken once per run of bricks on its grid, not per brick.
  std::vector<PoseBoxes> holders;
  uint32_t holdersOf = kInvalidIndex;
  for (const auto& [grid, local] : editLoad_.touched()) {
    if (edited[grid] != 1) continue;
    if (grid != holdersOf) holderPoses(holdersOf = grid, holders);
    for (size_t h = 0; h < holders.size(); ++h) {
      boxes.push_back(holders[h].worldBox(local));
      owners.push_back(gridBodies_[grid][h]);
    }
  }
  editedBoxes_.build(std::move(boxes), std::move(owners));
  auto touchesEdit = [&](const BodyPair& p) {
    for (const auto& side : {std::pair{p.a, p.b}, std::pair{p.b, p.a}}) {
      const uint32_t g = side.first, other = side.second;  // note: not a structured binding (clang 14 cannot capture one)
      if (!bodies_.shape[g].isGrid() || !edited[bodies_.shape[g].grid]) continue;
      if (edited[bodies_.shape[g].grid] == 2) return true;
      // note: how `other` moves relative to the edited grid: a crate riding a flying ship wakes for
      // a brick taken from under it, not for one its world-frame sweep (4 m/s) passes.
      float reach;
      const WorldAabb box = bodies_.translates(g) || bodies_.turns(g) ? boundsMovingBeside(other, g)
                            : other < hasEditBounds_.size() && hasEditBounds_[other] ? editBounds_[other]
                                                                                     : boundsOf(other, reach);
      if (editedBoxes_.any(box, [&](uint32_t holder) { return holder == g; })) return true;
    }
    return false;
  };
  // Each pair decided once (pairs_ is sorted), then the cache's entries looked up in it.
  std::vector<BodyPair> touched;
  for (const BodyPair& p : pairs_) {
    if (!touchesEdit(p)) continue;
    touched.push_back(p);
    for (uint32_t x : {p.a, p.b}) sleep_.wake(x);
  }
  const auto key = [](const BodyPair& p) { return (uint64_t(p.a) << 32) | p.b; };
  pairCache_.forget([&](const BodyPair& p) {
    const auto it = std::lower_bound(touched.begin(), touched.end(), p, [&](const BodyPair& x, const BodyPair& y) { return key(x) < key(y); });
    return it != touched.end() && key(*it) == key(p);
  });
}

void World::refreshStaleLinks() {
  // A split grid edited through editGrid(): its links are taken again (the removals made there
  // are not checked for parts that fell off: where they were is not known).
  for (uint32_t g = 0; g < grids_.size(); ++g)
    if (links_[g] && linksStale_[g]) {
      links_[g] = std::make_unique<BrickConnectivity>(*grids_[g]);
      linksStale_[g] = 0;
    }
}

EditLoad::Hooks World::editHooks() {
  const bool linked = std::any_of(links_.begin(), links_.end(), [](const auto& l) { return l != nullptr; });
  if (!linked && !recordingEdits_ && !renderChunks_) return {};
  EditLoad::Hooks hooks;
  hooks.beforeRemove = [this](uint32_t grid, uint32_t brick) {
    if (recordingEdits_) editLog_.bricks.push_back({grid, brick, false, grids_[grid]->brick(brick)});
    if (renderChunks_) renderChunks_->removing(grid, grids_[grid]->brick(brick));
    if (!links_[grid]) return;
    const auto t = Clock::now();
    links_[grid]->removing(brick, splitSeeds_[grid]);
    stats_.splitMs += msSince(t);
  };
  hooks.afterPlace = [this](uint32_t grid, uint32_t brick) {
    if (recordingEdits_) editLog_.bricks.push_back({grid, brick, true, grids_[grid]->brick(brick)});
    if (renderChunks_) renderChunks_->placed(grid, grids_[grid]->brick(brick));
    if (!links_[grid]) return;
    const auto t = Clock::now();
    links_[grid]->placed(*grids_[grid], brick);
    stats_.splitMs += msSince(t);
  };
  return hooks;
}

void World::recordEdits(bool on) {
  recordingEdits_ = on;
  editLog_.clear();
  betweenSteps_.clear();
}

void World::splitDetachedParts() {
  const auto t = Clock::now();
  std::vector<std::vector<uint32_t>> parts;
  const uint32_t count = uint32_t(grids_.size());  // parts made here split from the next frame on
  bool any = false;
  for (uint32_t g = 0; g < count; ++g) {
    if (!links_[g]) continue;
    any = true;
    if (splitSeeds_[g].empty()) continue;
    parts.clear();
    links_[g]->detached(splitSeeds_[g], parts);
    splitSeeds_[g].clear();
    const auto made = Clock::now();
    for (const std::vector<uint32_t>& part : parts) makeBodyOfPart(g, part);
    if (!parts.empty()) stats_.partBodiesMs += msSince(made);
    if (!parts.empty()) wholeGridEdits_.push_back(g);  // what rested on the parts moves with them
  }
  if (any) stats_.splitMs += msSince(t);
}

void World::makeBodyOfPart(uint32_t g, const std::vector<uint32_t>& part) {
  const uint32_t holder = gridBodies_[g].front();  // a split grid has one body (scene_validation)
  BrickGrid& old = *grids_[g];
  std::vector<uint32_t> ignored;
  if (part.size() < debrisBricks_[g]) {
    for (uint32_t id : part) {
      if (recordingEdits_) editLog_.bricks.push_back({g, id, false, old.brick(id)});
      if (renderChunks_) renderChunks_->removing(g, old.brick(id));
      links_[g]->removing(id, ignored);
      old.removeBrick(id);
    }
    stats_.debrisBricks += uint32_t(part.size());
    return;
  }
  // The part keeps its bricks' grid coordinates: its grid sits where the old one is. Its bricks
  // move over in bulk (one index build there, one bulk removal here) and take their links along.
  auto grid = std::make_unique<BrickGrid>(BrickGrid::Config(uint32_t(part.size() + 1024)));
  if (recordingEdits_)
    for (uint32_t id : part) editLog_.bricks.push_back({g, id, false, old.brick(id)});
  const std::vector<uint32_t> lamps = lightsOnPart(g, part);  // before the part's bricks leave
  BrickGrid::Move move = old.beginMove(part, *grid);
  const std::vector<uint32_t>& ids = move.newIds();
  std::unique_ptr<BrickConnectivity> partLinks;
  // The gather reads the old grid and writes each brick's new slot and entry once: in chunks at
  // once (it was 1.4 ms of serial time in a 50k-brick cut, with the part's bricks' first-touch
  // faults now in it). Then the part's index build, its mass, the old grid's bulk removal, its
  // bricks and mass, and the links' move touch five separate things. Their order splits them
  // between two threads by cost (oneTBB halves [0, 5) and the second thread takes [2, 5)): the
  // build with the old grid's bricks (Split_CutInTwo, 50k bricks, one thread: 3.9 + 0.5 ms)
  // beside the bulk removal, the part's mass and the links (2.4 + 0.8 + 1.2 ms); with four
  // threads or more the build alone is the longest. note: tried before the removal gave its
  // emptied pages back in runs (PoolIndexSpace::DeferPageRelease), this was slower than one
  // thread: a madvise per emptied block, each flushing the TLB of the core that was building.
  constexpr uint32_t kSteps = 5;
  const auto step = [&](uint32_t k) {
    if (k == 0) grid->receiveMoveIndex(move);
    else if (k == 1) old.releaseMoveBricks(move);
    else if (k == 2) old.releaseMoveIndex(move);
    else if (k == 3) grid->receiveMoveBricks(move);
    else partLinks = std::make_unique<BrickConnectivity>(*links_[g], part, ids);  // the old links, renumbered
  };
  const uint32_t n = uint32_t(part.size());
  if (n >= tuning::kParallelPartBricks) {
    jobs_.parallelFor(0, n, tuning::grainFor(n, tuning::kMinGatherGrain),
                      [&](uint32_t begin, uint32_t end) { old.gatherMove(move, begin, end); });
    jobs_.parallelFor(0, kSteps, 1, [&](uint32_t begin, uint32_t end) {
      for (uint32_t k = begin; k < end; ++k) step(k);
    });
  } else {
    old.gatherMove(move, 0, n);
    for (uint32_t k = 0; k < kSteps; ++k) step(k);
  }
  if (renderChunks_)  // the bricks as they were, now in the part's grid
    for (uint32_t id : ids) renderChunks_->removing(g, grid->brick(id));
  // Its centre of mass moves as that point of the old body did (v + w x r about the old body's
  // centre; a kinematic grid turns about its origin, which is its position); a static grid's
  // parts start at rest.
  const RigidTransform pose = bodies_.shapePose(holder);
  const Vec3d centre = pose.pointToWorld(grid->massProperties().centerOfMass.cast<float>());
  Vec3f v = Vec3f::Zero(), w = Vec3f::Zero();
  if (bodies_.motion[holder] != MotionType::Static) {
    w = bodies_.angularVelocity[holder];
    v = bodies_.linearVelocity[holder] + w.cross((centre - bodies_.position[holder]).cast<float>());
  }
  const uint32_t ng = uint32_t(grids_.size());
  const uint32_t body = addPartBody(std::move(grid), std::move(partLinks), debrisBricks_[g], gridNames_[g] + "/part" + std::to_string(++piecesMade_),
                                    pose, v, w);
  if (recordingEdits_) editLog_.splits.push_back({g, ng, body});
  moveLights(g, ng, lamps);
  ++stats_.splits;
}

uint32_t World::addPartBody(std::unique_ptr<BrickGrid> grid, std::unique_ptr<BrickConnectivity> links, uint32_t debris, std::string name,
                            const RigidTransform& pose, const Vec3f& v, const Vec3f& w) {
  const uint32_t ng = uint32_t(grids_.size());
  links_.push_back(std::move(links));
  linksStale_.push_back(0);
  splitSeeds_.emplace_back();
  debrisBricks_.push_back(debris);
  grids_.push_back(std::move(grid));
  gridNames_.push_back(std::move(name));
  gridLights_.emplace_back();
  const uint32_t body = addGridBody(ng, pose.translation, pose.rotation, MotionType::Dynamic, v.cast<double>(), w);
  gridBodies_.push_back({body});
  solidBodies_.push_back(body);
  solidIndexCurrent_ = false;
  nearSolid_.push_back(1);
  ghost_.push_back(0);  // note: read for every pair while some body depenetrates (a part made then overran it)
  sleep_.grow(bodies_.size());
  return body;
}

EditLoad::Blocked World::editBlockers() {
  if (!editLoad_.places()) return {};
  // Every dynamic body's box now (its bounds over the coming frame's motion); a planned brick is
  // tested where each body holding its grid holds it.
  std::vector<WorldAabb> boxes;
  std::vector<uint32_t> owners;
  editBounds_.resize(bodies_.size());
  hasEditBounds_.assign(bodies_.size(), 0);
  for (uint32_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_.motion[i] != MotionType::Dynamic) continue;
    float reach;
    boxes.push_back(boundsOf(i, reach));
    owners.push_back(i);
    if (bodies_.shape[i].isGrid() || bodies_.shape[i].isTerrain()) continue;
    editBounds_[i] = boxes.back();
    hasEditBounds_[i] = 1;
  }
  editBodies_.build(std::move(boxes), std::move(owners));
  // note: the holders' poses taken once per grid asked about, not once per planned brick.
  return [this, holders = std::vector<PoseBoxes>(), holdersOf = kInvalidIndex](uint32_t grid, const Aabb& local) mutable {
    if (grid != holdersOf) holderPoses(holdersOf = grid, holders);
    const auto other = [&](uint32_t body) { return !(bodies_.shape[body].isGrid() && bodies_.shape[body].grid == grid); };
    for (const PoseBoxes& holder : holders)
      if (editBodies_.any(holder.worldBox(local), other)) return true;
    return false;
  };
}

void World::refreshGridBodyMass(uint32_t body) {
  const MassProperties mass = grids_[bodies_.shape[body].grid]->massProperties();
  // note: a grid edited down to nothing keeps its last mass: it collides with nothing, but a
  // body with zero mass would break the solver's and integrator's divisions.
  if (!(mass.mass > 0)) return;
  // The grid stays where it is; the body frame (centre of mass, principal axes) moves inside
  // it. Every remaining brick keeps its velocity, so the new centre of mass moves at v + w x r
  // (r from the old centre to the new) and the spin is unchanged.
  const RigidTransform gridPose = bodies_.shapePose(body);
  const GridBodyFrame frame = gridBodyFrame(mass);
  const RigidTransform bodyPose = gridPose * frame.bodyInGrid;
  const Vec3f r = (bodyPose.translation - bodies_.position[body]).cast<float>();
  bodies_.linearVelocity[body] += bodies_.angularVelocity[body].cross(r);
  bodies_.position[body] = bodyPose.translation;
  bodies_.rotation[body] = bodyPose.rotation;
  bodies_.shapeFromBody[body] = frame.bodyInGrid.inverse();
  bodies_.inverseMass[body] = frame.inverseMass;
  bodies_.inverseInertia[body] = frame.inverseInertia;
  sleep_.wake(body);
}

void World::holderPoses(uint32_t grid, std::vector<PoseBoxes>& out) const {
  out.clear();
  for (uint32_t i : gridBodies_[grid]) out.emplace_back(bodies_.shapePose(i));
}

void World::runEdits() {
  ProfileZone z(profiler_, "edits", kEditStage, true);
  hasEditBounds_.clear();  // boxes are kept for one frame's edits only (editBlockers() takes them)
  editLog_.clear();
  if (recordingEdits_) {  // what removeBricks() and editGrid() did since the last step comes first
    std::swap(editLog_, betweenSteps_);
    std::sort(editLog_.wholeGrids.begin(), editLog_.wholeGrids.end());
    editLog_.wholeGrids.erase(std::unique(editLog_.wholeGrids.begin(), editLog_.wholeGrids.end()), editLog_.wholeGrids.end());
  }
  refreshStaleLinks();
  if (!editLoad_.empty()) {
    const auto load = Clock::now();
    const EditLoadStats e = editLoad_.apply(frame_, grids_, editedGrids_, editBlockers(), editHooks());
    stats_.bricksRemoved = e.removed;
    stats_.bricksPlaced = e.placed;
    stats_.editsSkipped = e.skipped;
    stats_.editMs = e.gridEditMs;
    stats_.editLoadMs = msSince(load) - e.gridEditMs - stats_.splitMs;  // the connectivity hooks are split time
  }
  splitDetachedParts();
  carveTerrains();
  const auto apply = Clock::now();
  const bool edited = !editedGrids_.empty();
  applyGridEdits();
  if (edited) stats_.editMs += msSince(apply);
}

void World::applyFrameEdits() {
  stats_ = StepStats{};
  profiler_.beginFrame(frame_);
  runEdits();
  profiler_.endFrame();
  ++frame_;
}

void World::step() {
  const auto t = Clock::now();
  stats_ = StepStats{};
  solidIndexCurrent_ = false;
  nearSolid_.assign(bodies_.size(), 0);
  profiler_.beginFrame(frame_);
  runEdits();
  advanceDepenetration();
  const float dt = float(scene_.settings.timestep / scene_.settings.substeps);
  for (int s = 0; s < scene_.settings.substeps; ++s) substep(dt, s);
  boundsCurrent_ = true;
  finishDepenetration();
  {
    ProfileZone z(profiler_, "rays (stage)");
    const auto rays = Clock::now();
    const RayLoadStats r =
        rayLoad_.fire(scene_.rays, frame_, bodies_, grids_, bounds_, jobs_, profiler_, scene_.settings.substeps * kStagesPerSubstep);
    if (r.rays > 0) {
      stats_.rays = r.rays;
      stats_.rayHits = r.hits;
      stats_.rayBoxTests = r.boxTests;
      stats_.raysMs = msSince(rays);
    }
  }
  ++frame_;
  if (render_) {
    // Frame steps 5-7 (world_render.h); the stage ids follow the ray load's.
    ProfileZone z(profiler_, "render (stage)");
    const auto chunks = Clock::now();
    {
      ProfileZone c(profiler_, "render chunks", renderStage(), true);
      refreshAttachments();
    }
    stats_.renderChunksMs = msSince(chunks);
    stats_.render = render_->run(bodies_, sleep_, jobs_, profiler_, renderStage());
    stats_.render.updateMs += stats_.renderChunksMs;
  }
  profiler_.endFrame();
  stats_.totalMs = msSince(t);
}

void World::setPoses(const std::vector<Vec3d>& positions, const std::vector<Quatf>& rotations) {
  const uint32_t n = bodies_.size();
  if (positions.size() != n || rotations.size() != n)
    throw InvalidInput("World::setPoses: " + std::to_string(positions.size()) + " positions and " + std::to_string(rotations.size()) +
                       " rotations for " + std::to_string(n) + " bodies");
  for (uint32_t i = 0; i < n; ++i) {
    requireFinite(positions[i], "World::setPoses", "position");
    requireUnitQuaternion(rotations[i], "World::setPoses", "rotation");
  }
  for (uint32_t i = 0; i < n; ++i) {
    bodies_.position[i] = positions[i];
    bodies_.rotation[i] = rotations[i].normalized();
  }
  pairCache_.forget([](const BodyPair&) { return true; });
  if (render_) render_->checkAllBodies();
  // Moved from outside: no step vouches for where bodies went (containment checks them all).
  nearSolid_.assign(n, 1);
  boundsCurrent_ = false;
  solidIndexCurrent_ = false;
  ++posesSet_;
}

void World::setKinematicVelocity(uint32_t body, const Vec3f& linear, const Vec3f& angular) {
  using scene_limits::kMaxAngularSpeed, scene_limits::kMaxSpeed;
  const char* what = "World::setKinematicVelocity";
  if (body >= bodies_.size())
    throw InvalidInput(std::string(what) + ": body " + std::to_string(body) + " of " + std::to_string(bodies_.size()));
  if (bodies_.motion[body] != MotionType::Kinematic)
    throw InvalidInput(std::string(what) + ": body " + std::to_string(body) + " is not kinematic");
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(linear[k]) || std::abs(linear[k]) > kMaxSpeed)
      throw InvalidInput(std::string(what) + ": linear velocity component " + std::to_string(k) + " is " + std::to_string(linear[k]) +
                         " (expected finite, at most " + std::to_string(kMaxSpeed) + " m/s)");
    if (!std::isfinite(angular[k]) || std::abs(angular[k]) > kMaxAngularSpeed)
      throw InvalidInput(std::string(what) + ": angular velocity component " + std::to_string(k) + " is " + std::to_string(angular[k]) +
                         " (expected finite, at most " + std::to_string(kMaxAngularSpeed) + " rad/s)");
  }
  bodies_.linearVelocity[body] = linear;
  bodies_.angularVelocity[body] = angular;
}

uint64_t World::stateHash() const {
  uint64_t h = 0;
  for (uint32_t i = 0; i < bodies_.size(); ++i) {
    for (int k = 0; k < 3; ++k) h = hashCombine(h, bitsOf(bodies_.position[i][k]));
    for (int k = 0; k < 4; ++k) h = hashCombine(h, bitsOf(bodies_.rotation[i].coeffs()[k]));
    for (int k = 0; k < 3; ++k) h = hashCombine(hashCombine(h, bitsOf(bodies_.linearVelocity[i][k])), bitsOf(bodies_.angularVelocity[i][k]));
  }
  return h;
}

double World::energy() const {
  double e = 0;
  const Vec3d g = scene_.settings.gravity;
  for (uint32_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_.motion[i] != MotionType::Dynamic) continue;
    const double m = 1.0 / bodies_.inverseMass[i];
    const Vec3f wl = bodies_.rotation[i].conjugate() * bodies_.angularVelocity[i];
    e += 0.5 * m * bodies_.linearVelocity[i].squaredNorm();
    e += 0.5 * double(wl.cwiseProduct(wl).dot(bodies_.inverseInertia[i].cwiseInverse()));
    e -= m * g.dot(bodies_.position[i]);
  }
  return e;
}

}  // namespace bw
