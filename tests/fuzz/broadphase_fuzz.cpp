// Fuzz target: the world's broadphase (IncrementalBroadphase) over a program of frames against
// brute force. Up to 96 proxies of up to 48 owners, static or moving, boxes from the shared
// lattices (sizes 0.001..10^4, anchors to 3*10^7, some bad: NaN, infinity, inverted); each frame
// moves, teleports, grows or shrinks some of them, turns some static or moving, drops or adds
// proxies and sometimes gives one owner two moving proxies. Every update must give exactly the
// brute-force pairs of owners, or refuse (InvalidInput) input that is bad, after which the next
// good frame must still be right; the moving tree validates after every frame.
#include <algorithm>
#include <stdexcept>
#include <vector>

#include "collision/core/errors.h"
#include "fuzz/box_choices.h"
#include "world/incremental_broadphase.h"

namespace {

using namespace bw;
using fuzz::FuzzInput;

constexpr uint32_t kMaxProxies = 96, kOwners = 48;
constexpr int kMaxFrames = 60;

struct Proxy {
  WorldAabb box;
  uint32_t owner;
  bool isStatic;
};

WorldAabb toWorld(const Aabb& b) { return {b.min.cast<double>(), b.max.cast<double>()}; }

bool good(const WorldAabb& b) { return b.min.allFinite() && b.max.allFinite() && (b.min.array() <= b.max.array()).all(); }

std::vector<BodyPair> brute(const std::vector<Proxy>& ps) {
  std::vector<BodyPair> out;
  for (size_t i = 0; i < ps.size(); ++i)
    for (size_t j = i + 1; j < ps.size(); ++j) {
      const Proxy& a = ps[i];
      const Proxy& b = ps[j];
      if ((a.isStatic && b.isStatic) || a.owner == b.owner || !a.box.overlaps(b.box)) continue;
      out.push_back({std::min(a.owner, b.owner), std::max(a.owner, b.owner)});
    }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// Whether the frame's input is one the broadphase must refuse: a bad box, or an owner with two
// moving proxies.
bool refusable(const std::vector<Proxy>& ps) {
  std::vector<uint32_t> moving;
  for (const Proxy& p : ps) {
    if (!good(p.box)) return true;
    if (!p.isStatic) moving.push_back(p.owner);
  }
  std::sort(moving.begin(), moving.end());
  return std::adjacent_find(moving.begin(), moving.end()) != moving.end();
}

// A new proxy: moving ones get owners of their own where they can (two moving proxies of one
// owner is an error the fuzzer should reach, but not every frame).
Proxy newProxy(FuzzInput& in, float anchor, const std::vector<Proxy>& ps) {
  Proxy p{toWorld(fuzz::fuzzBox(in, anchor)), 0, in.below(4) == 0};
  if (p.isStatic || in.below(16) == 0) {
    p.owner = in.below(kOwners);
    return p;
  }
  for (uint32_t tries = 0; tries < kOwners; ++tries) {
    p.owner = in.below(kOwners);
    if (std::none_of(ps.begin(), ps.end(), [&](const Proxy& q) { return !q.isStatic && q.owner == p.owner; })) break;
  }
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  const float anchor = in.pick(std::span<const float>(fuzz::kAnchors));
  std::vector<Proxy> ps;
  const uint32_t start = in.below(kMaxProxies);
  for (uint32_t i = 0; i < start; ++i) ps.push_back(newProxy(in, anchor, ps));
  IncrementalBroadphase bp;
  std::vector<WorldAabb> bounds;
  std::vector<uint8_t> isStatic;
  std::vector<uint32_t> owner;
  std::vector<BodyPair> pairs;
  for (int frame = 0; frame < kMaxFrames && !in.done(); ++frame) {
    // The proxies are listed in owner order, as the world lists them, or as they are.
    std::vector<Proxy> listed = ps;
    if (in.flag()) std::stable_sort(listed.begin(), listed.end(), [](const Proxy& a, const Proxy& b) { return a.owner < b.owner; });
    bounds.clear();
    isStatic.clear();
    owner.clear();
    for (const Proxy& p : listed) {
      bounds.push_back(p.box);
      isStatic.push_back(p.isStatic);
      owner.push_back(p.owner);
    }
    const bool bad = refusable(listed);
    try {
      bp.update(bounds, isStatic, pairs, nullptr, nullptr, -1, &owner);
      FUZZ_CHECK(!bad, "frame %d: bad input accepted", frame);
      const std::vector<BodyPair> expected = brute(listed);
      FUZZ_CHECK(pairs == expected, "frame %d: %zu pairs, brute force %zu (%zu proxies)", frame, pairs.size(), expected.size(), listed.size());
    } catch (const InvalidInput&) {
      FUZZ_CHECK(bad, "frame %d: good input refused", frame);
    }
    try {
      bp.movingTree().validate();
    } catch (const std::logic_error& e) {
      FUZZ_CHECK(false, "frame %d: %s", frame, e.what());
    }
    // The next frame's changes.
    const uint32_t changes = in.below(12);
    for (uint32_t c = 0; c < changes; ++c) {
      const uint32_t op = in.below(8);
      if (op == 7 || ps.empty()) {
        if (ps.size() < kMaxProxies) ps.push_back(newProxy(in, anchor, ps));
        continue;
      }
      Proxy& p = ps[in.below(uint32_t(ps.size()))];
      switch (op) {
        case 0:
        case 1: {  // creep: a few centimetres to a metre
          const double step = 0.01 * double(1 + in.below(100));
          for (int a = 0; a < 3; ++a) {
            const double d = (double(in.byte()) - 127.5) / 127.5 * step;
            p.box.min[a] += d;
            p.box.max[a] += d;
          }
          break;
        }
        case 2: p.box = toWorld(fuzz::fuzzBox(in, anchor)); break;  // a jump (or a bad box)
        case 3: {  // grows or shrinks about its centre
          const Vec3d c = (p.box.min + p.box.max) * 0.5, h = (p.box.max - p.box.min) * (in.flag() ? 0.25 : 1.0);
          p.box = {c - h, c + h};
          break;
        }
        case 4: p.isStatic = !p.isStatic; break;
        case 5: ps.erase(ps.begin() + (&p - ps.data())); break;
        case 6: p.owner = in.below(kOwners); break;  // may share a moving owner: refused
      }
    }
  }
  return 0;
}
