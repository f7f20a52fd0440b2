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

void Profiler::recordBeside(const char* name, int64_t beginNs, int64_t endNs, int32_t stage, uint32_t frame) {
  append(bufferForThisThread(), {name, beginNs, endNs, 0, stage, frame, false, true});
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
  return std::max({t, workMs / threads, besideSpanMs});
}

double WorkSpan::speedupBound(int threads) const {
  const double b = boundMs(threads);
  return b > 0 ? workMs / b : 1.0;
}

namespace {
// A frame's zones summed stage by stage: a frame has a few dozen stages, or thousands when a
// coloured island makes a stage of each colour and iteration. Zones of one stage mostly come
// one after another (checked first); other stages are found through an open-addressing table
// kept from frame to frame, and sorted once the frame is summed. (Searching a list for each
// stage was quadratic in them; sorting every zone cost more on frames of many jobs; a list kept
// sorted paid a search and an insert per stage, most stages arriving below the last one.)
class StageSums {
 public:
  void add(const ProfileEvent& e) {
    if (e.beside) {
      const double ms = double(e.endNs - e.beginNs) * 1e-6;
      besideWork_ += ms;
      besideLongest_ = std::max(besideLongest_, ms);
      return;
    }
    if (stages_.empty() || stages_[last_].stage != e.stage) last_ = slot(e.stage);
    StageTime& s = stages_[last_];
    const double ms = double(e.endNs - e.beginNs) * 1e-6;
    s.work += ms;
    s.longest = std::max(s.longest, ms);
    if (e.serial) s.serial += ms;
  }

  /// Sums of the stages added since the last call, in ascending stage order; then starts over.
  WorkSpan workSpan() {
    // Sorted through 8-byte keys (stage, biased so negative ids sort first, and slot).
    keys_.resize(stages_.size());
    for (uint32_t k = 0; k < stages_.size(); ++k) keys_[k] = uint64_t(uint32_t(stages_[k].stage) ^ 0x80000000u) << 32 | k;
    std::sort(keys_.begin(), keys_.end());
    WorkSpan ws;
    const size_t n = stages_.size();
    ws.stageWorkMs.resize(n);
    ws.stageSpanMs.resize(n);
    ws.stageIds.resize(n);
    for (size_t k = 0; k < n; ++k) {
      const StageTime& s = stages_[uint32_t(keys_[k])];
      const double span = std::max(s.longest, s.serial);
      ws.workMs += s.work;
      ws.spanMs += span;
      ws.stageWorkMs[k] = s.work;
      ws.stageSpanMs[k] = span;
      ws.stageIds[k] = s.stage;
    }
    ws.stages = int(n);
    ws.besideWorkMs = besideWork_;
    ws.besideSpanMs = besideLongest_;
    ws.workMs += besideWork_;
    ws.spanMs = std::max(ws.spanMs, besideLongest_);
    startOver();
    return ws;
  }

  /// Work and span of the stages added since the last call, in the order first met (no sort,
  /// no per-stage lists); then starts over.
  WorkSpanTotals totals() {
    WorkSpanTotals t;
    for (const StageTime& s : stages_) {
      t.workMs += s.work;
      t.spanMs += std::max(s.longest, s.serial);
    }
    t.stages = stages_.size();
    t.workMs += besideWork_;
    t.spanMs = std::max(t.spanMs, besideLongest_);
    startOver();
    return t;
  }

 private:
  static constexpr uint32_t kEmpty = ~0u;
  void startOver() {
    for (const StageTime& s : stages_) index_[s.bucket] = kEmpty;
    stages_.clear();
    last_ = 0;
    besideWork_ = besideLongest_ = 0;
  }
  uint32_t slot(int32_t stage) {
    if (index_.empty()) index_.assign(256, kEmpty);
    const size_t mask = index_.size() - 1;
    for (size_t h = hash(stage) & mask;; h = (h + 1) & mask) {
      if (index_[h] == kEmpty) {
        index_[h] = uint32_t(stages_.size());
        stages_.push_back(StageTime{stage, uint32_t(h)});
        if (stages_.size() * 2 > index_.size()) rebuildIndex();
        return uint32_t(stages_.size() - 1);
      }
      if (stages_[index_[h]].stage == stage) return index_[h];
    }
  }
  static size_t hash(int32_t stage) { return size_t((uint64_t(uint32_t(stage)) * 0x9E3779B97F4A7C15ull) >> 32); }
  // Twice as large, the frame's stages placed again (one allocation, not a node per stage: a
  // node-based map cost more than the search it replaced).
  void rebuildIndex() {
    const size_t size = index_.size() * 2;
    index_.assign(size, kEmpty);
    for (size_t k = 0; k < stages_.size(); ++k) {
      size_t h = hash(stages_[k].stage) & (size - 1);
      while (index_[h] != kEmpty) h = (h + 1) & (size - 1);
      index_[h] = uint32_t(k);
      stages_[k].bucket = uint32_t(h);
    }
  }
  struct StageTime {
    int32_t stage = 0;
    uint32_t bucket = 0;                       // its slot in index_
    double work = 0, longest = 0, serial = 0;  // ms: all zones, the longest zone, the serial zones
  };
  std::vector<StageTime> stages_;  // in the order the frame first met them
  std::vector<uint32_t> index_;    // open addressing: stages_ slot, or kEmpty
  std::vector<uint64_t> keys_;
  uint32_t last_ = 0;
  double besideWork_ = 0, besideLongest_ = 0;  // ms: the beside zones (outside the stages)
};

// Calls done(sums) after adding each frame 0 .. frames-1's job zones to one StageSums. The zones
// are grouped by frame with a counting sort, buffer by buffer and each in its order, so a
// frame's zones are added in the order workSpan(frame) adds them: O(events) and a few
// allocations (a StageSums per frame, its stage list searched for each stage, cost ~480
// instructions a zone on stack10's run).
template <class Buffers, class Done>
void sumFrameByFrame(const Buffers& buffers, uint32_t frames, int32_t firstStage, int32_t lastStage, Done&& done) {
  const auto wanted = [&](const ProfileEvent& e) { return e.frame < frames && e.stage >= firstStage && e.stage <= lastStage; };
  std::vector<uint32_t> firstOfFrame(size_t(frames) + 1, 0);
  for (const auto& b : buffers)
    for (const ProfileEvent& e : b->events)
      if (wanted(e)) ++firstOfFrame[e.frame + 1];
  for (uint32_t f = 0; f < frames; ++f) firstOfFrame[f + 1] += firstOfFrame[f];
  std::vector<const ProfileEvent*> byFrame(firstOfFrame[frames]);
  std::vector<uint32_t> next(firstOfFrame.begin(), firstOfFrame.end() - 1);
  for (const auto& b : buffers)
    for (const ProfileEvent& e : b->events)
      if (wanted(e)) byFrame[next[e.frame]++] = &e;
  StageSums stages;
  for (uint32_t f = 0; f < frames; ++f) {
    for (uint32_t k = firstOfFrame[f]; k < firstOfFrame[f + 1]; ++k) stages.add(*byFrame[k]);
    done(stages);
  }
}

}  // namespace

std::vector<WorkSpan> Profiler::workSpans(uint32_t frames, int32_t firstStage, int32_t lastStage) const {
  std::vector<WorkSpan> out;
  out.reserve(frames);
  std::lock_guard<std::mutex> lock(registry_);
  sumFrameByFrame(buffers_, frames, std::max(firstStage, 0), lastStage, [&](StageSums& stages) { out.push_back(stages.workSpan()); });
  return out;
}

WorkSpanTotals Profiler::workSpanTotals(uint32_t frames) const {
  WorkSpanTotals all;
  std::lock_guard<std::mutex> lock(registry_);
  sumFrameByFrame(buffers_, frames, 0, INT32_MAX, [&](StageSums& stages) {
    const WorkSpanTotals t = stages.totals();
    all.workMs += t.workMs;
    all.spanMs += t.spanMs;
    all.stages += t.stages;
  });
  return all;
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
    nlohmann::json args{{"frame", e.frame}, {"stage", e.stage}};
    if (e.beside) args["beside"] = true;
    trace.push_back({{"name", e.name},
                     {"ph", "X"},
                     {"ts", double(e.beginNs) * 1e-3},
                     {"dur", double(e.endNs - e.beginNs) * 1e-3},
                     {"pid", 1},
                     {"tid", e.thread},
                     {"args", std::move(args)}});
  }
  std::ofstream out(path);
  if (!out) throw std::runtime_error("Profiler::writeChromeTrace: cannot open '" + path + "' for writing");
  out << nlohmann::json{{"traceEvents", trace}, {"displayTimeUnit", "ms"}}.dump();
  if (!out) throw std::runtime_error("Profiler::writeChromeTrace: writing '" + path + "' failed");
}

}  // namespace bw
