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

// A frame's zones summed stage by stage. Zones mostly come stage by stage, and a frame has a
// few dozen stages: a search of the list from its end finds them. But a coloured island gives a
// frame thousands of stages, a stage per colour and iteration, where that search was quadratic
// (28 ms of demolition's 0.4 s run): past kListedStages the stages are found through a hash
// table. (Sorting every zone by stage instead cost more on frames of few stages and many jobs.)
class StageSums {
 public:
  void add(const ProfileEvent& e) {
    if (stages_.empty() || stages_[last_].stage != e.stage) last_ = slot(e.stage);
    StageTime& s = stages_[last_];
    const double ms = double(e.endNs - e.beginNs) * 1e-6;
    s.work += ms;
    s.longest = std::max(s.longest, ms);
    if (e.serial) s.serial += ms;
  }

  WorkSpan workSpan() {
    std::sort(stages_.begin(), stages_.end(), [](const StageTime& a, const StageTime& b) { return a.stage < b.stage; });
    index_.clear();  // the slots moved: a later add() finds them by the list again
    last_ = 0;
    WorkSpan ws;
    ws.stageWorkMs.reserve(stages_.size());
    ws.stageSpanMs.reserve(stages_.size());
    ws.stageIds.reserve(stages_.size());
    for (const StageTime& s : stages_) {
      const double span = std::max(s.longest, s.serial);
      ws.workMs += s.work;
      ws.spanMs += span;
      ws.stageWorkMs.push_back(s.work);
      ws.stageSpanMs.push_back(span);
      ws.stageIds.push_back(s.stage);
    }
    ws.stages = int(stages_.size());
    return ws;
  }

 private:
  static constexpr size_t kListedStages = 128;
  static constexpr uint32_t kEmpty = ~0u;
  uint32_t slot(int32_t stage) {
    if (index_.empty()) {
      for (size_t k = stages_.size(); k-- > 0;)
        if (stages_[k].stage == stage) return uint32_t(k);
      stages_.push_back(StageTime{stage});
      if (stages_.size() > kListedStages) rebuildIndex();
      return uint32_t(stages_.size() - 1);
    }
    const size_t mask = index_.size() - 1;
    for (size_t h = hash(stage) & mask;; h = (h + 1) & mask) {
      if (index_[h] == kEmpty) {
        index_[h] = uint32_t(stages_.size());
        stages_.push_back(StageTime{stage});
        if (stages_.size() * 2 > index_.size()) rebuildIndex();
        return uint32_t(stages_.size() - 1);
      }
      if (stages_[index_[h]].stage == stage) return index_[h];
    }
  }
  static size_t hash(int32_t stage) { return size_t((uint64_t(uint32_t(stage)) * 0x9E3779B97F4A7C15ull) >> 32); }
  // An open-addressing table of stage slots (one allocation, not a node per stage: a frame of
  // a few hundred stages made a node-based map cost more than the search it replaced).
  void rebuildIndex() {
    size_t size = 256;
    while (size < stages_.size() * 4) size *= 2;
    index_.assign(size, kEmpty);
    for (size_t k = 0; k < stages_.size(); ++k) {
      size_t h = hash(stages_[k].stage) & (size - 1);
      while (index_[h] != kEmpty) h = (h + 1) & (size - 1);
      index_[h] = uint32_t(k);
    }
  }
  std::vector<StageTime> stages_;
  std::vector<uint32_t> index_;  // once there are more than kListedStages
  uint32_t last_ = 0;
};
}  // namespace

std::vector<WorkSpan> Profiler::workSpans(uint32_t frames) const {
  std::vector<StageSums> perFrame(frames);
  {
    std::lock_guard<std::mutex> lock(registry_);
    for (const auto& b : buffers_)
      for (const ProfileEvent& e : b->events)
        if (e.frame < frames && e.stage >= 0) perFrame[e.frame].add(e);
  }
  std::vector<WorkSpan> out;
  out.reserve(frames);
  for (StageSums& stages : perFrame) out.push_back(stages.workSpan());
  return out;
}

WorkSpan Profiler::workSpan(uint32_t frame) const {
  StageSums stages;
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
      if (e.frame == frame && e.stage >= 0) stages.add(e);
    }
  }
  return stages.workSpan();
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
