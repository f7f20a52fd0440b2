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

void Profiler::record(const char* name, int64_t beginNs, int64_t endNs, int32_t stage) {
  ThreadBuffer& b = bufferForThisThread();
  b.events.push_back({name, beginNs, endNs, b.thread, stage, frame_});
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
  for (auto& b : buffers_) b->events.clear();
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
using StageTimes = std::map<int32_t, std::pair<double, double>>;  // stage -> (work, longest job)

void addZone(StageTimes& stages, const ProfileEvent& e) {
  const double ms = double(e.endNs - e.beginNs) * 1e-6;
  auto& s = stages[e.stage];
  s.first += ms;
  s.second = std::max(s.second, ms);
}

WorkSpan toWorkSpan(const StageTimes& stages) {
  WorkSpan ws;
  for (const auto& [stage, s] : stages) {
    ws.workMs += s.first;
    ws.spanMs += s.second;
    ws.stageWorkMs.push_back(s.first);
    ws.stageSpanMs.push_back(s.second);
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
  for (const StageTimes& stages : perFrame) out.push_back(toWorkSpan(stages));
  return out;
}

WorkSpan Profiler::workSpan(uint32_t frame) const {
  StageTimes stages;
  std::lock_guard<std::mutex> lock(registry_);
  for (const auto& b : buffers_)
    for (const ProfileEvent& e : b->events)
      if (e.frame == frame && e.stage >= 0) addZone(stages, e);
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
