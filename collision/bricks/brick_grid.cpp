#include "collision/bricks/brick_grid.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>

#include "collision/core/argument_checks.h"
#include "collision/core/assert.h"
#include "collision/core/errors.h"

namespace bw {

// A few ulps of the largest coordinate a ray or sweep query involves (the grid's bounds and the
// query's own point): covers the rounding differences between slab tests and exact shape tests.
float BrickGrid::roundingMargin(const Vec3f& queryPoint) const {
  const Aabb all = index_.rootBounds();
  float reach = queryPoint.cwiseAbs().maxCoeff();
  if (!all.isEmpty()) reach = std::max({reach, all.min.cwiseAbs().maxCoeff(), all.max.cwiseAbs().maxCoeff()});
  return reach * 0x1p-20f + std::numeric_limits<float>::min();
}

BrickGrid::BrickGrid(const Config& config)
    : config_(config),
      bricks_(config.maxBricks, "BrickGrid bricks"),
      index_(OctoBvh::Config{config.maxBricks}) {
  for (float d : config.density)
    if (!(d > 0.f) || !std::isfinite(d)) throw InvalidInput("BrickGrid: every material density must be finite and > 0");
}

uint32_t BrickGrid::placeBrick(const Brick& b) {
  validateBrick(b, "BrickGrid::placeBrick");
  const Aabb box = brickBounds(b);
  const uint32_t id = bricks_.allocate();
  uint32_t element;
  try {
    element = index_.insert(box, b.filter, id);  // validates range; throws before modifying
  } catch (...) {
    bricks_.free(id);
    throw;
  }
  bricks_.get<0>(id) = b;
  bricks_.get<1>(id) = element;
  if (!referenceSet_) {
    // note: moments are summed about the first brick's position, not the grid origin, so a grid
    // built far from its origin does not lose its inertia to cancellation in double.
    reference_ = b.position.cast<double>();
    referenceSet_ = true;
  }
  moments_.add(brickMoments(b, config_.density[b.material], reference_));
  peakSecond_ = std::max(peakSecond_, moments_.value().second.trace());
  ++edits_;
  return id;
}

std::vector<uint32_t> BrickGrid::placeBricks(const std::vector<Brick>& bricks) {
  if (bricks_.size() != 0) throw InvalidInput("BrickGrid::placeBricks: the grid must be empty (it has " + std::to_string(bricks_.size()) + " bricks)");
  if (bricks.size() > config_.maxBricks)
    throw CapacityExceeded("BrickGrid::placeBricks: " + std::to_string(bricks.size()) + " bricks exceed the grid's capacity of " +
                           std::to_string(config_.maxBricks));
  std::vector<Aabb> bounds;
  bounds.reserve(bricks.size());
  for (const Brick& b : bricks) {
    validateBrick(b, "BrickGrid::placeBricks");
    bounds.push_back(brickBounds(b));
  }
  return placeValidBricks(bricks, bounds);
}

std::vector<uint32_t> BrickGrid::placeValidBricks(const std::vector<Brick>& bricks, const std::vector<Aabb>& bounds) {
  std::vector<uint32_t> ids;
  ids.reserve(bricks.size());
  for (size_t i = 0; i < bricks.size(); ++i) ids.push_back(bricks_.allocate());
  indexValidBricksOrFree(ids, bricks, bounds);
  addValidBricks(ids, bricks);
  return ids;
}

void BrickGrid::indexValidBricksOrFree(const std::vector<uint32_t>& ids, std::span<const Brick> bricks, std::span<const Aabb> bounds) {
  std::vector<uint32_t> filters;
  filters.reserve(bricks.size());
  for (const Brick& b : bricks) filters.push_back(b.filter);
  try {
    // (bulkLoad validates every box before building: the range of a brick's bounds is checked there)
    indexValidBricks(ids, bounds, filters, false);
  } catch (...) {
    for (uint32_t id : ids) bricks_.free(id);
    throw;
  }
}

void BrickGrid::indexMovedBricksOrFree(const Move& m) {
  try {
    indexMovedBricks(m);
  } catch (...) {
    for (uint32_t id : m.newIds_) bricks_.free(id);
    throw;
  }
}

void BrickGrid::indexMovedBricks(const Move& m) { indexValidBricks(m.newIds_, m.bounds_, m.filters_, true); }

void BrickGrid::indexValidBricks(const std::vector<uint32_t>& ids, std::span<const Aabb> bounds, std::span<const uint32_t> filters,
                                 bool boundsFromIndex) {
  const std::vector<uint32_t> elements =
      boundsFromIndex ? index_.bulkLoadValid(bounds, filters, ids) : index_.bulkLoad(bounds, filters, ids);
  for (size_t i = 0; i < ids.size(); ++i) bricks_.get<1>(ids[i]) = elements[i];
}

void BrickGrid::addValidBricks(const std::vector<uint32_t>& ids, std::span<const Brick> bricks) {
  for (size_t i = 0; i < bricks.size(); ++i) {
    bricks_.get<0>(ids[i]) = bricks[i];
    if (!referenceSet_) {
      reference_ = bricks[i].position.cast<double>();  // as placeBrick: moments about the first brick
      referenceSet_ = true;
    }
    moments_.add(brickMoments(bricks[i], config_.density[bricks[i].material], reference_));
  }
  peakSecond_ = std::max(peakSecond_, moments_.value().second.trace());
  ++edits_;
}

std::vector<uint32_t> BrickGrid::moveBricks(std::span<const uint32_t> ids, BrickGrid& into) {
  Move move = prepareMove(ids, into);
  // note: the bricks are valid (they were placed here) and `into` was checked: placing them
  // there cannot throw but for an allocation failure, so nothing is half-moved.
  into.receiveMove(move);
  releaseMove(move);
  return std::move(move.newIds_);
}

BrickGrid::Move BrickGrid::prepareMove(std::span<const uint32_t> ids, BrickGrid& into) {
  Move m = beginMove(ids, into);
  gatherMove(m, 0, m.size());
  return m;
}

BrickGrid::Move BrickGrid::beginMove(std::span<const uint32_t> ids, BrickGrid& into) {
  const char* context = "BrickGrid::moveBricks";
  if (&into == this) throw InvalidInput(std::string(context) + ": a grid cannot move bricks into itself");
  if (into.bricks_.size() != 0)
    throw InvalidInput(std::string(context) + ": the grid moved into must be empty (it has " + std::to_string(into.bricks_.size()) + " bricks)");
  if (into.config_.density != config_.density) throw InvalidInput(std::string(context) + ": the grids' material densities differ");
  if (ids.size() > into.config_.maxBricks)
    throw CapacityExceeded(std::string(context) + ": " + std::to_string(ids.size()) + " bricks exceed the capacity of the grid moved into (" +
                           std::to_string(into.config_.maxBricks) + ")");
  std::vector<uint8_t> listed(bricks_.indexBound(), 0);
  for (uint32_t id : ids) {
    if (!bricks_.isLive(id)) throw InvalidInput(std::string(context) + ": brick " + std::to_string(id) + " is not in this grid");
    if (listed[id]++) throw InvalidInput(std::string(context) + ": brick " + std::to_string(id) + " is listed twice");
  }
  Move m;
  m.from_ = this;
  m.into_ = &into;
  m.ids_.assign(ids.begin(), ids.end());
  resizeForOverwrite(m.bounds_, ids.size());
  resizeForOverwrite(m.elements_, ids.size());
  resizeForOverwrite(m.filters_, ids.size());
  m.newIds_.resize(ids.size());
  // (gatherMove writes every brick and receiveMoveIndex every element: left unconstructed)
  into.bricks_.allocateManyForOverwrite(uint32_t(ids.size()), m.newIds_.data());
  m.fromEdits_ = edits_;
  m.reference_ = reference_;
  return m;
}

void BrickGrid::gatherMove(Move& m, size_t begin, size_t end) const {
  BW_ASSERT(m.from_ == this && begin <= end && end <= m.size());
  const std::vector<uint32_t>& ids = m.ids_;
  // note: the ids come in a search's order, so each brick and its index record is a cache miss;
  // asked for ahead (the record half as far ahead as its brick, whose element handle names it),
  // the gather of a 50k-brick part took 3.5 -> 1.9 ms (perf samples).
  constexpr size_t kAhead = 16;
  for (size_t i = begin; i < end; ++i) {
    if (i + 2 * kAhead < end) {
      __builtin_prefetch(&bricks_.get<0>(ids[i + 2 * kAhead]));
      __builtin_prefetch(&bricks_.get<1>(ids[i + 2 * kAhead]));
    }
    if (i + kAhead < end) index_.prefetchElement(bricks_.get<1>(ids[i + kAhead]));
    const uint32_t id = ids[i];
    const Brick& b = bricks_.get<0>(id);
    m.into_->bricks_.get<0>(m.newIds_[i]) = b;  // straight to its slot there (nothing else writes it)
    const uint32_t e = bricks_.get<1>(id);
    m.bounds_[i] = index_.bounds(e);  // the brick's bounds as indexed (brickBounds of it)
    m.elements_[i] = e;
    m.filters_[i] = b.filter;
  }
}

void BrickGrid::receiveMove(Move& m) {
  BW_ASSERT(m.into_ == this);
  indexMovedBricksOrFree(m);
  receiveMoveBricks(m);
}

void BrickGrid::receiveMoveIndex(Move& m) {
  BW_ASSERT(m.into_ == this);
  indexMovedBricks(m);
}

// note: the moved bricks' moments are taken about the old grid's reference, so the one sum
// serves both grids: each brick's moments were computed twice (about each grid's first brick)
// and summed twice, 29 M of a 50k-brick cut's 111 M instructions (Split_CutInTwo).
void BrickGrid::receiveMoveBricks(Move& m) {
  BW_ASSERT(m.into_ == this);
  // (this grid was empty: prepareMove checked) Its reference is the old grid's, so the sum
  // addValidBricks makes here is the part's sum about it.
  if (!m.newIds_.empty()) {
    reference_ = m.reference_;
    referenceSet_ = true;
  }
  // The bricks are in place (gatherMove wrote them): their moments, in the ids' order.
  for (const uint32_t id : m.newIds_) {
    const Brick& b = bricks_.get<0>(id);
    moments_.add(brickMoments(b, config_.density[b.material], reference_));
  }
  peakSecond_ = std::max(peakSecond_, moments_.value().second.trace());
  ++edits_;
  m.moments_ = moments_;
  rebaseIfCancelling();  // a small part far from the old grid's reference point
  finishMoveMassStep(m);
}

void BrickGrid::finishMoveMassStep(Move& m) {
  // acq_rel: the step that comes second sees everything the first one wrote (the freed ids, or
  // the part's sum).
  if (std::atomic_ref<uint32_t>(m.massSteps_).fetch_add(1, std::memory_order_acq_rel) == 0) return;
  BrickGrid& from = *m.from_;
  if (from.bricks_.size() == 0) {
    from.moments_.clear();  // exactly empty
    from.peakSecond_ = 0;
    from.referenceSet_ = false;
  } else {
    from.moments_.subtract(m.moments_);
    from.rebaseIfCancelling();
  }
}

void BrickGrid::releaseMove(Move& m) {
  requireUnedited(m);  // before either step: a refused move leaves the grid as it was
  releaseMoveIndex(m);
  releaseMoveBricks(m);
}

void BrickGrid::requireUnedited(const Move& m) const {
  if (edits_ != m.fromEdits_)
    throw InvalidInput("BrickGrid::releaseMove: the grid was edited after prepareMove, or the move was released already");
}

void BrickGrid::releaseMoveIndex(Move& m) {
  BW_ASSERT(m.from_ == this);
  index_.removeMany(m.elements_);  // (gives emptied pages back in runs)
}

// note: reads the bricks and the moments only (the moments' rebase walks the bricks left), never
// the index, so it runs beside releaseMoveIndex.
void BrickGrid::releaseMoveBricks(Move& m) {
  BW_ASSERT(m.from_ == this);
  // prepareMove found the ids live and distinct; nothing has edited the grid since (this step
  // is the one that counts the move), so they still are.
  requireUnedited(m);
  bricks_.freeManyChecked(m.ids_);
  ++edits_;
  finishMoveMassStep(m);
}

void BrickGrid::removeBrick(uint32_t id) {
  if (!bricks_.isLive(id))
    throw InvalidInput("BrickGrid::removeBrick: brick " + std::to_string(id) + " is not in this grid");
  const Brick b = bricks_.get<0>(id);
  index_.remove(bricks_.get<1>(id));
  bricks_.free(id);
  if (bricks_.size() == 0) {
    moments_.clear();  // exactly empty
    peakSecond_ = 0;
    referenceSet_ = false;
  } else {
    moments_.subtract(brickMoments(b, config_.density[b.material], reference_));
    rebaseIfCancelling();
  }
  ++edits_;
}

void BrickGrid::prefetchRemovals(std::span<const uint32_t> ids) const {
  uint32_t elements[kPrefetchGroup];
  for (size_t first = 0; first < ids.size(); first += kPrefetchGroup) {
    const std::span<const uint32_t> group = ids.subspan(first, std::min(kPrefetchGroup, ids.size() - first));
    for (uint32_t id : group) {
      if (!bricks_.isLive(id)) continue;
      bricks_.prefetchFree(id);  // the brick itself: column 0
      __builtin_prefetch(&bricks_.get<1>(id));
    }
    size_t n = 0;
    for (uint32_t id : group)
      if (bricks_.isLive(id)) elements[n++] = bricks_.get<1>(id);
    index_.prefetchPaths({elements, n});
  }
}

void BrickGrid::prefetchPlacements(std::span<const Brick> bricks) const {
  Aabb bounds[kPrefetchGroup];
  for (size_t first = 0; first < bricks.size(); first += kPrefetchGroup) {
    const std::span<const Brick> group = bricks.subspan(first, std::min(kPrefetchGroup, bricks.size() - first));
    size_t n = 0;
    for (const Brick& b : group) {
      try {
        validateBrick(b, "BrickGrid::prefetchPlacements");  // (placeBrick reports a bad brick)
      } catch (const InvalidInput&) {
        continue;
      }
      bounds[n++] = brickBounds(b);
    }
    index_.prefetchInsertPaths({bounds, n});
  }
}

// note: the moments are summed about a reference point. When the bricks left are far from it
// compared with their own spread (the bricks around it were removed), their inertia about the
// centre of mass is the difference of two nearly equal numbers (the grid-edit fuzz target:
// 2e-7 of the inertia lost, bricks 8 km from the first). Once the offset's share exceeds
// kRebaseRatio of the spread (about 20 bits lost), the sums are recomputed about the centre of
// mass: O(bricks), after which the centre must move by a thousand radii of gyration, which
// takes edits of most of the mass, before it happens again.
// note: the compensated sums keep an error of about eps^2 times the largest value they ever
// held; once what is left is 2^-30 of that peak (a 10^4 m brick came and went among 1 mm ones:
// 1e-3 of their inertia, the grid-edit fuzz target again), they are recomputed as well.
void BrickGrid::rebaseIfCancelling() {
  constexpr double kRebaseRatio = double(1 << 20), kPeakRatio = double(1 << 30);
  const ShapeMoments sum = moments_.value();
  if (sum.volume <= 0) return;
  const Vec3d comRel = sum.first / sum.volume;
  const double offset = sum.volume * comRel.squaredNorm();
  const double spread = sum.second.trace() - offset;  // sum of m |x - centre|^2
  if (offset <= kRebaseRatio * spread && sum.second.trace() * kPeakRatio >= peakSecond_) return;
  reference_ += comRel;
  moments_.clear();
  bricks_.forEachLive([&](uint32_t id) {
    const Brick& b = bricks_.get<0>(id);
    moments_.add(brickMoments(b, config_.density[b.material], reference_));
  });
  peakSecond_ = moments_.value().second.trace();
}

MassProperties BrickGrid::massProperties() const {
  MassProperties m;
  const ShapeMoments sum = moments_.value();
  if (bricks_.size() == 0 || sum.volume <= 0) return m;
  m.mass = sum.volume;
  const Vec3d comRel = sum.first / m.mass;
  const Mat3d c = sum.second - m.mass * comRel * comRel.transpose();
  m.inertia = c.trace() * Mat3d::Identity() - c;
  m.centerOfMass = reference_ + comRel;
  return m;
}

GridRayHit BrickGrid::raycast(const Ray& ray, uint32_t mask, QueryStats* stats) const {
  requireFinite(ray.origin, "BrickGrid::raycast", "ray.origin");
  requireFinite(ray.dir, "BrickGrid::raycast", "ray.dir");
  if (ray.parallelMask == 7)
    throw InvalidInput("BrickGrid::raycast: ray.dir has zero length (every component is zero or denormal)");
  if (!(ray.maxT >= 0.f))
    throw InvalidInput("BrickGrid::raycast: ray.maxT is " + std::to_string(ray.maxT) + ", expected >= 0 (+inf: unlimited)");
  // note: the index's slab tests (bounds times 1/dir) and rayBrick (plane distances divided in the
  // brick's frame) round differently, so by one ulp the index could reject a brick the ray only
  // grazes, or whose exact entry ties the best hit. Traversing bounds grown by a few ulps of the
  // largest coordinate involved keeps the index conservative: every brick rayBrick hits within
  // maxT is tested, so the result is rayBrick's smallest t (of bricks tied there, the first met).
  const RayHit h = index_.sweepClosest(ray, Vec3f::Constant(roundingMargin(ray.origin)), mask,
                                       [&](uint32_t e, float, float tMax, float& tHit) {
                                         Vec3f n;
                                         return rayBrick(brick(index_.payload(e)), ray, tMax, tHit, n);
                                       },
                                       stats);
  GridRayHit out;
  if (!h.hit()) return out;
  out.brick = index_.payload(h.element);
  float t;
  rayBrick(brick(out.brick), ray, ray.maxT, t, out.normal);
  out.t = h.t;
  return out;
}

GridSweepHit BrickGrid::sweep(const QueryShape& shape, const Quatf& rotation, const Vec3f& from, const Vec3f& to,
                              uint32_t mask, QueryStats* stats) const {
  shape.validate("BrickGrid::sweep");
  requireFinite(from, "BrickGrid::sweep", "from");
  requireFinite(to, "BrickGrid::sweep", "to");
  requireUnitQuaternion(rotation, "BrickGrid::sweep", "rotation");
  // note: sweepShapeBrick stops within its gap tolerance (1e-4 x (1 + brick half size)) of first
  // touch, possibly earlier in t than where the bounds meet; growing the traversed bounds by the
  // largest such tolerance (bounded by half the grid's extent) and a rounding margin keeps the
  // index conservative, so the result is the smallest fraction over every brick.
  const float tolerance = 1e-4f * (1.f + 0.5f * index_.rootBounds().extent().cwiseMax(0.f).maxCoeff());
  const Vec3f grow = rotation.toRotationMatrix().cwiseAbs() * shape.localHalfExtents() +
                     Vec3f::Constant(tolerance + roundingMargin(from));
  const Ray ray = Ray::make(from, to - from, 1.f);
  GridSweepHit out;
  const RayHit h = index_.sweepClosest(ray, grow, mask,
                                       [&](uint32_t e, float, float tMax, float& tHit) {
                                         float f;
                                         Vec3f n, p;
                                         if (!sweepShapeBrick(shape, rotation, from, to, brick(index_.payload(e)), f, n, p)) return false;
                                         tHit = f;
                                         return f <= tMax;
                                       },
                                       stats);
  if (!h.hit()) return out;
  out.brick = index_.payload(h.element);
  sweepShapeBrick(shape, rotation, from, to, brick(out.brick), out.fraction, out.normal, out.point);
  return out;
}

void BrickGrid::overlapBricks(const Aabb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats) const {
  // note: infinite bounds are accepted (an unbounded box, or Aabb::empty()); NaN would silently
  // overlap nothing.
  for (int i = 0; i < 3; ++i) {
    if (std::isnan(box.min[i])) throw InvalidInput(std::string("BrickGrid::overlapBricks: box.min.") + "xyz"[i] + " is NaN");
    if (std::isnan(box.max[i])) throw InvalidInput(std::string("BrickGrid::overlapBricks: box.max.") + "xyz"[i] + " is NaN");
  }
  index_.overlap(box, mask, [&](uint32_t e) { out.push_back(index_.payload(e)); }, stats);
}

void BrickGrid::collideLocal(const QueryShape& shape, const LocalPose& pose, const ContactParams& params,
                             std::vector<LocalContact>& out, ContactStats* stats) const {
  const Mat3f R = pose.rotation.toRotationMatrix();
  const Vec3f e = R.cwiseAbs() * shape.localHalfExtents() + Vec3f::Constant(std::max(params.speculativeMargin, 0.f));
  const Aabb box{pose.position - e, pose.position + e};
  ContactStats local;
  LocalContact buf[kMaxContactsPerBrick];
  auto onBrick = [&](uint32_t element) {
    const uint32_t id = index_.payload(element);
    ++local.bricksTested;
    const int n = collideShapeBrick(shape, pose, brick(id), id, params.speculativeMargin, buf);
    out.insert(out.end(), buf, buf + n);
  };
  auto onLod = [&](const LodBox& lod) {
    // A small subtree collides as one solid box of its tight bounds.
    Brick b;
    b.position = lod.bounds.center();
    b.halfSize = lod.bounds.halfExtent().cwiseMax(Vec3f::Constant(kMinBrickHalfSize));
    b.shape = BrickShape::Box;
    const int n = collideShapeBrick(shape, pose, b, kLodFeature | local.lodBoxes, params.speculativeMargin, buf);
    ++local.lodBoxes;
    out.insert(out.end(), buf, buf + n);
  };
  const size_t before = out.size();
  index_.overlapLod(box, params.mask, params.lodFraction, onBrick, onLod, &local.index);
  local.rawContacts = uint32_t(out.size() - before);
  if (stats) {
    stats->index += local.index;
    stats->bricksTested += local.bricksTested;
    stats->lodBoxes += local.lodBoxes;
    stats->rawContacts += local.rawContacts;
  }
}

size_t BrickGrid::collide(const RigidTransform& gridPose, const QueryShape& shape, const RigidTransform& shapePose,
                          const ContactParams& params, ContactScratch& scratch, std::vector<Contact>& out,
                          ContactStats* stats) const {
  gridPose.validate("BrickGrid::collide (grid pose)");
  shapePose.validate("BrickGrid::collide (shape pose)");
  shape.validate("BrickGrid::collide");
  validateContactParams(params, "BrickGrid::collide");
  return collideChecked(gridPose, shape, shapePose, params, scratch, out, stats);
}

void BrickGrid::validateContactParams(const ContactParams& params, const char* context) {
  if (params.maxContacts < 1 || params.maxContacts > 64)
    throw InvalidInput(std::string(context) + ": params.maxContacts is " + std::to_string(params.maxContacts) + ", expected 1..64");
  requireInRange(params.lodFraction, 0.0, 1.0, context, "params.lodFraction");
  requireFinite(params.speculativeMargin, context, "params.speculativeMargin");
}

size_t BrickGrid::collideChecked(const RigidTransform& gridPose, const QueryShape& shape, const RigidTransform& shapePose,
                                 const ContactParams& params, ContactScratch& scratch, std::vector<Contact>& out,
                                 ContactStats* stats) const {
  const LocalPose pose{gridPose.pointToLocal(shapePose.translation), gridPose.rotationToLocal(shapePose.rotation).normalized()};
  scratch.raw.clear();
  collideLocal(shape, pose, params, scratch.raw, stats);
  const int kept = keepDeepestPerShapePart(scratch.raw.data(), int(scratch.raw.size()));
  const int n = reduceManifold(scratch.raw.data(), kept, params.maxContacts);
  for (int i = 0; i < n; ++i) {
    const LocalContact& c = scratch.raw[i];
    out.push_back({gridPose.pointToWorld(c.position), gridPose.directionToWorld(c.normal), c.depth, c.feature, c.material});
  }
  return size_t(n);
}

}  // namespace bw
