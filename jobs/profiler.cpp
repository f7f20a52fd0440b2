#include "jobs/profiler.h"

#include <algorithm>
#include <atomic>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace bw {

namespace {

// A thread's events in blocks of kBlock that never move: appending never copies what was
// recorded. (A vector doubling as a run grows copied its whole log, tens of MB at a million
// events, inside whichever gap between zones it fell: up to 0.9 ms read as serial glue.)
class EventLog {
 public:
  static constexpr size_t kBlock = 16384;
  size_t size() const { return size_; }
  const ProfileEvent& operator[](size_t k) const { return blocks_[k / kBlock][k % kBlock]; }
  void push_back(const ProfileEvent& e) {
    if (size_ == blocks_.size() * kBlock) blocks_.push_back(std::make_unique<ProfileEvent[]>(kBlock));
    blocks_[size_ / kBlock][size_ % kBlock] = e;
    ++size_;
  }
  void clear() { size_ = 0; }  // the blocks stay, to be filled again
  struct Iterator {
    const EventLog* log;
    size_t k;
    const ProfileEvent* at;  // event k
    const ProfileEvent& operator*() const { return *at; }
    Iterator& operator++() {
      ++k;
      at = k % kBlock != 0 ? at + 1 : k < log->size_ ? log->blocks_[k / kBlock].get() : nullptr;
      return *this;
    }
    bool operator!=(const Iterator& o) const { return k != o.k; }
  };
  Iterator begin() const { return {this, 0, size_ ? blocks_[0].get() : nullptr}; }
  Iterator end() const { return {this, size_, nullptr}; }

 private:
  std::vector<std::unique_ptr<ProfileEvent[]>> blocks_;
  size_t size_ = 0;
};

}  // namespace

struct Profiler::ThreadBuffer {
  uint32_t thread;
  EventLog events;
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
  for (const auto& b : buffers_)
    for (const ProfileEvent& e : b->events) all.push_back(e);
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

double WorkSpan::boundMs(int threads) const { return boundMsWithHandOvers(threads, 0.0); }

double WorkSpan::boundMsWithHandOvers(int threads, double handOverMs) const {
  const double charge = threads > 1 ? 2.0 * handOverMs : 0.0;  // one thread hands nothing over
  double t = glueMs;
  for (size_t s = 0; s < stageWorkMs.size(); ++s)
    t += std::max(stageWorkMs[s] / threads, stageSpanMs[s]) + (stageWorkMs[s] > stageSpanMs[s] ? charge : 0.0);
  return std::max({t, workMs / threads, besideSpanMs});
}

double WorkSpan::speedupBound(int threads) const {
  const double b = boundMs(threads);
  return b > 0 ? workMs / b : 1.0;
}

namespace {

// Glue (see WorkSpan) of frames [firstFrame, firstFrame + glue.size()) from each thread's events
// in recording order: the gap before a staged zone whose stage differs from the previous staged
// zone's of the same frame on this thread (a zone that begins exactly where the one before it
// ended continues that zone's job: the chain keeps its first zone's stage). A frame with staged
// zones from two threads has none.
struct FrameGlue {
  static constexpr uint32_t kNoThread = ~0u;
  int64_t ns = 0;
  uint32_t thread = kNoThread;
  bool oneThread = true;
  double ms() const { return oneThread ? double(ns) * 1e-6 : 0.0; }
};

// Fed one thread's events in recording order (a new walker per thread).
class GlueWalker {
 public:
  GlueWalker(uint32_t thread, uint32_t firstFrame, std::vector<FrameGlue>& glue) : thread_(thread), firstFrame_(firstFrame), glue_(glue) {}
  void add(const ProfileEvent& e) {
    if (e.stage < 0) return;  // envelopes (around stages) and zones outside the stages
    const bool sameFrame = last_ && last_->frame == e.frame;
    if (e.beside) {
      // A beside job this thread ran (inline, with one thread): its time is beside work, not glue.
      if (sameFrame) lastEnd_ = std::max(lastEnd_, e.endNs);
      return;
    }
    const bool continues = sameFrame && e.beginNs == last_->endNs;
    if (e.frame >= firstFrame_ && e.frame - firstFrame_ < glue_.size()) {
      FrameGlue& g = glue_[e.frame - firstFrame_];
      if (g.thread == FrameGlue::kNoThread) g.thread = thread_;
      g.oneThread = g.oneThread && g.thread == thread_;
      if (sameFrame && !continues && chainStage_ != e.stage && e.beginNs > lastEnd_) g.ns += e.beginNs - lastEnd_;
    }
    if (!continues) chainStage_ = e.stage;
    lastEnd_ = sameFrame ? std::max(lastEnd_, e.endNs) : e.endNs;
    last_ = &e;
  }

 private:
  uint32_t thread_, firstFrame_;
  std::vector<FrameGlue>& glue_;
  const ProfileEvent* last_ = nullptr;  // the previous staged zone
  int32_t chainStage_ = 0;              // the stage of the first zone of last_'s back-to-back chain
  int64_t lastEnd_ = 0;                 // the latest end in its frame so far
};

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

  /// The frame's glue (see WorkSpan), added to its work and span by the next workSpan() or totals().
  void setGlue(double ms) { glueMs_ = ms; }

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
    ws.glueMs = glueMs_;
    ws.workMs += besideWork_ + glueMs_;
    ws.spanMs = std::max(ws.spanMs + glueMs_, besideLongest_);
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
    t.glueMs = glueMs_;
    t.workMs += besideWork_ + glueMs_;
    t.spanMs = std::max(t.spanMs + glueMs_, besideLongest_);
    startOver();
    return t;
  }

 private:
  static constexpr uint32_t kEmpty = ~0u;
  void startOver() {
    for (const StageTime& s : stages_) index_[s.bucket] = kEmpty;
    stages_.clear();
    last_ = 0;
    besideWork_ = besideLongest_ = glueMs_ = 0;
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
  double glueMs_ = 0;
};

// Calls done(sums) after adding each frame 0 .. frames-1's job zones (and, for the whole frame:
// every stage wanted, its glue) to one StageSums. The zones
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
  // Glue needs every staged zone: between two wanted stages may lie one that is not.
  const bool withGlue = firstStage <= 0 && lastStage == INT32_MAX;
  std::vector<FrameGlue> glue(withGlue ? frames : 0);
  for (const auto& b : buffers) {
    GlueWalker walker(b->thread, 0, glue);
    for (const ProfileEvent& e : b->events) {
      if (withGlue) walker.add(e);
      if (wanted(e)) byFrame[next[e.frame]++] = &e;
    }
  }
  StageSums stages;
  for (uint32_t f = 0; f < frames; ++f) {
    for (uint32_t k = firstOfFrame[f]; k < firstOfFrame[f + 1]; ++k) stages.add(*byFrame[k]);
    if (!glue.empty()) stages.setGlue(glue[f].ms());
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
    all.glueMs += t.glueMs;
    all.stages += t.stages;
  });
  return all;
}

WorkSpan Profiler::workSpan(uint32_t frame) const {
  StageSums stages;
  std::vector<FrameGlue> glue(1);
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
    GlueWalker walker(b->thread, frame, glue);
    for (size_t k = begin; k < end; ++k) {
      const ProfileEvent& e = b->events[k];
      if (e.frame == frame && e.stage >= 0) stages.add(e);
      walker.add(e);
    }
  }
  stages.setGlue(glue[0].ms());
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
