// The concave builds of issue 19's scenes: a chain link (a ring whose hole another link passes
// through) and a docking hangar (a slot a ship flies into). A grid's convex approximation fills
// both holes, so they are what two-way grid pairs (grid_pair.h) are for.
#include <algorithm>
#include <cmath>

#include "collision/content/build_writer.h"
#include "collision/core/seeded_random.h"

namespace bw {

using namespace buildgen;

GeneratedBuild generateChainLink(uint64_t /*seed: a link has one shape*/, float scale) {
  requireScale(scale, 0.1, 64, "generateChainLink");
  const LinkDimensions d = chainLinkDimensions(scale);
  const float e = d.cell;
  // Cells of edge e centred at ((i + 0.5) e, (j + 0.5) e, (k + 0.5) e), i in [-nx, nx) etc.
  const int nx = int(std::ceil((d.arcRadius + d.wireRadius) / e)) + 1;
  const int ny = int(std::ceil(d.wireRadius / e)) + 1;
  const int nz = int(std::ceil((d.straight * 0.5f + d.arcRadius + d.wireRadius) / e)) + 1;
  const float r2 = d.wireRadius * d.wireRadius, halfStraight = d.straight * 0.5f;
  // A cell is solid when its centre is within the wire radius of the centre line: the points
  // at arcRadius from the segment x = y = 0, |z| <= straight / 2, in the XZ plane.
  auto solid = [&](int i, int j, int k) {
    const float x = (float(i) + 0.5f) * e, y = (float(j) + 0.5f) * e, z = (float(k) + 0.5f) * e;
    const float dz = std::max(std::abs(z) - halfStraight, 0.f);
    const float inPlane = std::sqrt(x * x + dz * dz) - d.arcRadius;  // sqrt is correctly rounded everywhere
    return inPlane * inPlane + y * y <= r2;
  };
  return runBuild("chain_link", [&](BuildWriter& w) {
    w.part("link");
    // Runs of solid cells along Z become one brick each: 216 bricks (long runs on the straight
    // sides, short ones where the wire bends across Z).
    for (int j = -ny; j < ny; ++j)
      for (int i = -nx; i < nx; ++i)
        for (int k = -nz; k < nz;) {
          if (!solid(i, j, k)) {
            ++k;
            continue;
          }
          int end = k + 1;
          while (end < nz && solid(i, j, end)) ++end;
          const Vec3f lo(float(i) * e, float(j) * e, float(k) * e), hi(float(i + 1) * e, float(j + 1) * e, float(end) * e);
          w.add((lo + hi) * 0.5f, (hi - lo) * 0.5f, BuildMaterial::Metal);
          k = end;
        }
    w.interior(d.hole);
  });
}

LinkDimensions chainLinkDimensions(float scale) {
  LinkDimensions d;
  d.cell = kMicro * scale;
  d.wireRadius = 0.24f * scale;
  d.arcRadius = 0.72f * scale;
  d.straight = 0.96f * scale;
  // An open box in the hole: the wire's cells reach at most half a cell diagonal (sqrt 3 / 2
  // of e) beyond its radius, so the hole is clear within `clear` of the segment x = 0,
  // |z| <= straight / 2; a box reaching 0.7 of that along x and past the segment's ends keeps
  // its corners inside (0.7^2 + 0.7^2 < 1).
  const float clear = d.arcRadius - d.wireRadius - 0.87f * d.cell, inset = 0.7f * clear;
  d.hole = Aabb{Vec3f(-inset, -d.wireRadius, -(d.straight * 0.5f + inset)), Vec3f(inset, d.wireRadius, d.straight * 0.5f + inset)};
  return d;
}

GeneratedBuild generateHangar(uint64_t seed, float scale) {
  requireScale(scale, 0.25, 16, "generateHangar");
  const float s = std::sqrt(scale);
  const float length = snap(96.f * s, 3.2f, 16.f), width = snap(16.f * s, 3.2f, 6.4f), height = snap(24.f * s, 1.6f, 6.4f);
  const float t = 0.8f;  // skin thickness
  const float hw = width * 0.5f;
  return runBuild("hangar", [&](BuildWriter& w) {
    SeededRandom r(seed);
    // Glass panels in the side walls, seeded: a wall panel's place is taken by a glass one of
    // the same size (the walls stay closed), on courses that are not shifted by the running
    // bond (even courses: z a multiple of 3.2).
    std::vector<Aabb> windows;
    for (float x = 3.2f; x + 3.2f <= length - 3.2f; x += 6.4f) {
      const float z0 = snap(float(r.uniform(2.0, double(height) - 4.0)), 3.2f, 3.2f);
      windows.push_back(Aabb{Vec3f(x, -hw - t - 1.f, z0), Vec3f(x + 3.2f, hw + t + 1.f, z0 + 1.6f)});
    }
    w.part("floor");
    tile(w, Vec3f(0, -hw - t, -t), Vec3f(length, hw + t, 0), Vec3f(3.2f, 3.2f, t), BuildMaterial::Metal);
    w.part("walls");
    for (float y0 : {-hw - t, hw})
      tile(w, Vec3f(0, y0, 0), Vec3f(length, y0 + t, height), Vec3f(3.2f, t, 1.6f), BuildMaterial::Metal, windows, 0);
    w.part("windows", kBuildFilterDetail);
    for (const Aabb& win : windows)
      for (float y0 : {-hw - t, hw})
        w.add(Vec3f(win.center().x(), y0 + t * 0.5f, win.center().z()), Vec3f(1.6f, t * 0.5f, 0.8f), BuildMaterial::Glass);
    w.part("roof");
    tile(w, Vec3f(0, -hw - t, height), Vec3f(length, hw + t, height + t), Vec3f(3.2f, 3.2f, t), BuildMaterial::Metal);
    w.part("back wall");
    tile(w, Vec3f(length, -hw - t, -t), Vec3f(length + t, hw + t, height + t), Vec3f(t, 3.2f, 1.6f), BuildMaterial::Metal, {}, 1);
    // Frames around the outside every 8 m (the first one is the mouth's), each a ring of four beams.
    w.part("frames");
    for (float x = 0.f; x + t <= length; x += 8.f) {
      for (float y0 : {-hw - 2.f * t, hw + t}) w.addBox(Vec3f(x, y0, -2.f * t), Vec3f(x + t, y0 + t, height + 2.f * t), BuildMaterial::Metal);
      for (float z0 : {-2.f * t, height + t}) w.addBox(Vec3f(x, -hw - t, z0), Vec3f(x + t, hw + t, z0 + t), BuildMaterial::Metal);
    }
    for (float x = 4.f; x < length; x += 8.f) w.light(Vec3f(x, 0.f, height - 1.f), 10.f);
    w.interior(Aabb{Vec3f(0, -hw, 0), Vec3f(length, hw, height)});
  });
}

}  // namespace bw
