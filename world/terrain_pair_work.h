#pragma once
/// The per-substep scratch of World::terrainPairs (world/terrain_pairs.cpp), kept between steps
/// so a steady-state step allocates nothing: the queries, each one's plan, and the pieces its
/// candidate triangles are cut into (so one body lying across many triangles is spread over
/// several jobs), each piece with its own output.
#include <cstdint>
#include <vector>

#include "collision/bricks/query_shape.h"
#include "collision/core/rigid_transform.h"
#include "collision/terrain/terrain_contacts.h"

namespace bw {

struct TerrainPairWork {
  struct Query {
    uint32_t pair, body, terrain;
    uint32_t brick = kWholeBody;  // a small grid's brick (queried brick by brick), or the whole body
    RigidTransform pose;  // the body's shape (or its grid's hull) in the world
    QueryShape shape;
    float margin = 0.f;
    bool cached = false;  // planned from cached chunks (else queried again in pair order)
    bool wet = false;
    WaterContact water;
  };
  static constexpr uint32_t kWholeBody = ~0u;
  /// A pair's queries: one, or one per brick of a small grid (kBrickwiseGridBricks).
  struct Group {
    uint32_t pair, firstQuery, queryCount;
  };
  struct PieceOutput {
    std::vector<Contact> contacts;
    std::vector<Vec3f> faceNormals;
  };

  std::vector<Query> queries;
  std::vector<Group> groups;               // in pair order; their queries consecutive
  std::vector<TerrainContactPlan> plans;   // one per query (grows, never shrinks)
  /// Query i's pieces are [pieceStart[i], pieceStart[i + 1]) (plan writes each query's count at
  /// i + 1, cut sums them); its candidate triangles in runs of trianglesPerPiece, in order.
  std::vector<uint32_t> pieceStart;
  std::vector<uint8_t> queryRepeats;       // plan: query i's body was queried already
  std::vector<PieceOutput> pieceOutputs;   // one per piece (grows, never shrinks)
  std::vector<Vec3f> faceNormals;          // the apply stage's scratch
  /// select's per-pair and per-chunk counts: a pair's queries (kNoQuery: not a terrain pair
  /// this substep), a chunk's queries, groups, hulls to make and small grids queried brick by
  /// brick (entry c + 1 for chunk c, then turned into offsets).
  static constexpr uint32_t kNoQuery = ~0u;
  struct SelectChunk {
    uint32_t queries = 0, groups = 0, hulls = 0, brickwise = 0;
  };
  std::vector<uint32_t> pairQueries;
  std::vector<SelectChunk> selectChunks;
  /// finish's per-job counts of the groups it completed (all queries cached, buoyancy done),
  /// and whether the job left a group for apply.
  struct FinishChunk {
    uint32_t contacts = 0, floating = 0;
    bool applyLeft = false;
  };
  std::vector<FinishChunk> finishChunks;
  std::vector<uint8_t> bodyQueried;        // per body: has a whole-body query this substep (all 0 between; atomic_ref)
  bool bodiesUnique = true;                // no body has two queries (then buoyancy runs per query in parallel)
};

}  // namespace bw
