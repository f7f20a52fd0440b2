#include "jobs/profiler.h"

#include <algorithm>
#include <atomic>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace bw {

struct Profiler::ThreadBuffer {
  uint32_t thread;
  std::vector<ProfileEvent> events;
  // Where each run of one frame's events starts: {frame, first event}. Frames arrive in
  // ascending order from a world, so workSpan(frame) finds its events by binary search
  // (O(events of that frame)); a buffer that ever went back to an earlier frame is scanned whole.
  std::vector<std::pair<uint32_t, size_t>> frameStarts;
  bool framesAscending = true;
};

namespace {

std::atomic<uint64_t> nextProfilerId{1};

// The calling thread's buffers, one per profiler it has recorded into (usually one). Profiler
// ids are never reused, so entries of destroyed profilers can never match again.
struct ThreadSlot {
  uint64_t profiler;
  void* buffer;
};
thread_local std::vector<ThreadSlot> tlsSlots;

}  // namespace

Profiler::Profiler() : epoch_(std::chrono::steady_clock::now()), id_(nextProfilerId.fetch_add(1)) {}
Profiler::~Profiler() = default;

Profiler::ThreadBuffer& Profiler::bufferForThisThread() {
  for (const ThreadSlot& s : tlsSlots)
    if (s.profiler == id_) return *static_cast<ThreadBuffer*>(s.buffer);
  std::lock_guard<std::mutex> lock(registry_);
  buffers_.push_back(std::make_unique<ThreadBuffer>());
  ThreadBuffer& b = *buffers_.back();
  b.thread = uint32_t(buffers_.size() - 1);
  b.events.reserve(4096);
  tlsSlots.push_back({id_, &b});
  return b;
}

void Profiler::record(const char* name, int64_t beginNs, int64_t endNs, int32_t stage, bool serial) {
  append(bufferForThisThread(), {name, beginNs, endNs, 0, stage, frame_, serial});
}

void Profiler::recordInFrame(const char* name, int64_t beginNs, int64_t endNs, int32_t stage, uint32_t frame) {
  append(bufferForThisThread(), {name, beginNs, endNs, 0, stage, frame, false});
}

void Profiler::append(ThreadBuffer& b, ProfileEvent e) {
  if (b.frameStarts.empty() || b.frameStarts.back().first != e.frame) {
    if (!b.frameStarts.empty() && b.frameStarts.back().first > e.frame) b.framesAscending = false;
    b.frameStarts.push_back({e.frame, b.events.size()});
  }
  e.thread = b.thread;
  b.events.push_back(e);
}

std::vector<ProfileEvent> Profiler::events() const {
  std::vector<ProfileEvent> all;
  std::lock_guard<std::mutex> lock(registry_);
  for (const auto& b : buffers_) all.insert(all.end(), b->events.begin(), b->events.end());
  std::sort(all.begin(), all.end(), [](const ProfileEvent& a, const ProfileEvent& b) {
    if (a.beginNs != b.beginNs) return a.beginNs < b.beginNs;
    if (a.thread != b.thread) return a.thread < b.thread;
    return a.endNs < b.endNs;
  });
  return all;
}

void Profiler::clear() {
  std::lock_guard<std::mutex> lock(registry_);
  for (auto& b : buffers_) {
    b->events.clear();
    b->frameStarts.clear();
    b->framesAscending = true;
  }
}

double WorkSpan::boundMs(int threads) const {
  double t = 0;
  for (size_t s = 0; s < stageWorkMs.size(); ++s) t += std::max(stageWorkMs[s] / threads, stageSpanMs[s]);
  return t;
}

double WorkSpan::speedupBound(int threads) const {
  const double b = boundMs(threads);
  return b > 0 ? workMs / b : 1.0;
}

namespace {
struct StageTime {
  int32_t stage = 0;
  double work = 0, longest = 0, serial = 0;  // ms: all zones, the longest zone, the serial zones
};
// A frame has a few dozen stages at most and its zones come stage by stage: a flat list searched
// from its end beats a map (the whole run's work/span is taken after every `run`).
using StageTimes = std::vector<StageTime>;

void addZone(StageTimes& stages, const ProfileEvent& e) {
  const double ms = double(e.endNs - e.beginNs) * 1e-6;
  auto it = std::find_if(stages.rbegin(), stages.rend(), [&](const StageTime& s) { return s.stage == e.stage; });
  StageTime& s = it != stages.rend() ? *it : stages.emplace_back(StageTime{e.stage});
  s.work += ms;
  s.longest = std::max(s.longest, ms);
  if (e.serial) s.serial += ms;
}

WorkSpan toWorkSpan(StageTimes& stages) {
  std::sort(stages.begin(), stages.end(), [](const StageTime& a, const StageTime& b) { return a.stage < b.stage; });
  WorkSpan ws;
  ws.stageWorkMs.reserve(stages.size());
  ws.stageSpanMs.reserve(stages.size());
  ws.stageIds.reserve(stages.size());
  for (const StageTime& s : stages) {
    const int32_t stage = s.stage;
    const double span = std::max(s.longest, s.serial);
    ws.workMs += s.work;
    ws.spanMs += span;
    ws.stageWorkMs.push_back(s.work);
    ws.stageSpanMs.push_back(span);
    ws.stageIds.push_back(stage);
  }
  ws.stages = int(stages.size());
  return ws;
}
}  // namespace

std::vector<WorkSpan> Profiler::workSpans(uint32_t frames) const {
  std::vector<StageTimes> perFrame(frames);
  {
    std::lock_guard<std::mutex> lock(registry_);
    for (const auto& b : buffers_)
      for (const ProfileEvent& e : b->events)
        if (e.frame < frames && e.stage >= 0) addZone(perFrame[e.frame], e);
  }
  std::vector<WorkSpan> out;
  out.reserve(frames);
  for (StageTimes& stages : perFrame) out.push_back(toWorkSpan(stages));
  return out;
}

WorkSpan Profiler::workSpan(uint32_t frame) const {
  StageTimes stages;
  std::lock_guard<std::mutex> lock(registry_);
  for (const auto& b : buffers_) {
    size_t begin = 0, end = b->events.size();
    if (b->framesAscending) {
      const auto& starts = b->frameStarts;
      const auto it = std::lower_bound(starts.begin(), starts.end(), frame,
                                       [](const std::pair<uint32_t, size_t>& s, uint32_t f) { return s.first < f; });
      if (it == starts.end() || it->first != frame) continue;
      begin = it->second;
      end = it + 1 == starts.end() ? b->events.size() : (it + 1)->second;
    }
    for (size_t k = begin; k < end; ++k) {
      const ProfileEvent& e = b->events[k];
      if (e.frame == frame && e.stage >= 0) addZone(stages, e);
    }
  }
  return toWorkSpan(stages);
}

void Profiler::writeChromeTrace(const std::string& path) const {
  nlohmann::json trace = nlohmann::json::array();
  for (const ProfileEvent& e : events()) {
    trace.push_back({{"name", e.name},
                     {"ph", "X"},
                     {"ts", double(e.beginNs) * 1e-3},
                     {"dur", double(e.endNs - e.beginNs) * 1e-3},
                     {"pid", 1},
                     {"tid", e.thread},
                     {"args", {{"frame", e.frame}, {"stage", e.stage}}}});
  }
  std::ofstream out(path);
  if (!out) throw std::runtime_error("Profiler::writeChromeTrace: cannot open '" + path + "' for writing");
  out << nlohmann::json{{"traceEvents", trace}, {"displayTimeUnit", "ms"}}.dump();
  if (!out) throw std::runtime_error("Profiler::writeChromeTrace: writing '" + path + "' failed");
}

}  // namespace bw
