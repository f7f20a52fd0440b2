#pragma once
/// Profiling zones for the frame's job graph, written as a Chrome trace (JSON trace events,
/// opens in Perfetto or chrome://tracing), and the work/span figures of a frame.
///
///   bw::Profiler prof;
///   prof.beginFrame(frameIndex);
///   { bw::ProfileZone z(prof, "contacts", /*stage*/ 2); ... }   // on any thread
///   prof.endFrame();
///   prof.writeChromeTrace("frame.json");
///   bw::WorkSpan ws = prof.workSpan(frameIndex);
///
/// Each thread records into its own buffer (found through a thread_local slot registered once
/// per thread and profiler), so recording is a clock read and a vector append with no shared
/// atomics or locks on the hot path. Buffers are merged when read.
/// Thread safety: zones may be recorded from any thread between beginFrame and endFrame; the
/// reading functions (events, writeChromeTrace, workSpan) need all zones of the frame closed.
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace bw {

/// One closed zone.
struct ProfileEvent {
  const char* name;     ///< static string
  int64_t beginNs;      ///< since the profiler's epoch
  int64_t endNs;
  uint32_t thread;      ///< dense thread index (registration order)
  int32_t stage;        ///< frame stage, or -1 for zones outside the stage structure
  uint32_t frame;
  bool serial = false;  ///< runs under a lock shared by every thread (see WorkSpan)
  bool beside = false;  ///< runs beside the frame's stages, no stage waiting for it (see WorkSpan)
};

/// Work and span of one frame, from its job zones (those with stage >= 0).
/// Stages run one after another; jobs inside a stage are independent. So the frame's critical
/// path is the sum over stages of their longest job, and with p threads a stage takes at least
/// max(work / p, longest job): the speedup bound at p threads is work / sum of those.
/// Serial zones (work done under one lock every thread takes, like a mutex command queue's
/// pushes) cannot overlap each other however many threads run, so a stage's span is at least
/// the sum of its serial zones.
/// Beside zones (JobSystem::runBeside: a job a worker runs while the stages go on, which no
/// stage waits for, like the render thread's wake) are outside the stages' chain: they add to
/// the work, and the frame takes at least their longest with p threads, not their sum.
/// Glue: in a frame whose staged zones all ran on one thread (a 1-thread run), the time from
/// one stage's zone to the next zone of another stage is serial code outside every zone (a
/// stage's setup, a loop nobody zoned, starting a parallelFor); it is in the work and the span,
/// and every bound pays it whole. crate_pile's glue was 194-260 us a frame against a ~500 us span
/// (session 42), so a bound without it promised a 16-thread machine what it cannot do. Gaps
/// between zones of one stage (a parallelFor's jobs one after another) are its jobs' own
/// scheduling, paid on whichever thread runs them: not glue. A job may split its time into zones
/// of two stages recorded back to back (the second begins at the first's end, one clock read):
/// the chain counts as its first zone's stage, so the gaps between such jobs of one loop are
/// its scheduling too (the transform update's jobs, update then submission, made 61 gaps a
/// frame of "glue" on crates_on_grid, 10 us). With several threads a thread's
/// gaps include waiting for the others, so such frames have no glue figure (0).
struct WorkSpan {
  double workMs = 0;           ///< sum of all job durations, beside zones and glue included
  double spanMs = 0;           ///< sum over stages of the longest job (or the longest beside zone), plus glue
  double glueMs = 0;           ///< serial time between stages outside any zone (see above)
  double besideWorkMs = 0, besideSpanMs = 0;  ///< the beside zones' sum and longest
  int stages = 0;
  /// Lower bound on the frame time with p threads: the stages' chain, each stage
  /// max(work / p, longest job), plus the glue; or all the work over p, or the longest beside zone.
  double boundMs(int threads) const;
  double speedupBound(int threads) const;  ///< workMs / boundMs(p)
  /// boundMs(threads) with every stage of several jobs (work above its longest job) charged two
  /// hand-overs of `handOverMs` with more than one thread: its jobs reach the other threads
  /// through a cache line, and its end reaches the next stage through another. The plain bound
  /// charges nothing for them, and a frame of ~60 stages of a few microseconds pays them whole
  /// (monument ran slower on two threads than on one with 160-ns hand-overs; profiles/RESULTS.md
  /// session 49). One thread hands nothing over: boundMs(1).
  double boundMsWithHandOvers(int threads, double handOverMs) const;
  std::vector<double> stageWorkMs, stageSpanMs;
  std::vector<int32_t> stageIds;  ///< the stage id of each entry above, ascending
};

/// Work and span summed over frames (what a run reports), without the per-stage lists.
struct WorkSpanTotals {
  double workMs = 0, spanMs = 0, glueMs = 0;
  uint64_t stages = 0;
};

class Profiler {
 public:
  Profiler();
  ~Profiler();
  Profiler(const Profiler&) = delete;
  Profiler& operator=(const Profiler&) = delete;

  /// Recording is on by default; off makes zones cost one branch.
  void setEnabled(bool on) { enabled_ = on; }
  bool enabled() const { return enabled_; }

  void beginFrame(uint32_t frame) { frame_ = frame; }
  void endFrame() {}
  uint32_t frame() const { return frame_; }

  /// Nanoseconds since this profiler was created (steady clock).
  int64_t now() const {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - epoch_).count();
  }
  /// Appends a closed zone from the calling thread (serial: see WorkSpan).
  void record(const char* name, int64_t beginNs, int64_t endNs, int32_t stage, bool serial = false);
  /// The same for a thread that runs beside the frames (a render thread): the zone belongs to
  /// `frame` as given, since frame() is the controlling thread's and not safe to read here.
  void recordInFrame(const char* name, int64_t beginNs, int64_t endNs, int32_t stage, uint32_t frame);
  /// A beside zone (see WorkSpan) of `frame`, from any thread (a worker runs it while the
  /// controlling thread has gone on, maybe to the next frame).
  void recordBeside(const char* name, int64_t beginNs, int64_t endNs, int32_t stage, uint32_t frame);

  /// All recorded events, sorted by (begin, thread, end).
  std::vector<ProfileEvent> events() const;
  /// Work/span of one frame's job zones, in O(events of that frame) when frames were recorded
  /// in ascending order (a world's are).
  WorkSpan workSpan(uint32_t frame) const;
  /// Work/span of frames 0 .. frames-1 in one pass over the events (workSpan per frame would
  /// read every event once per frame); of the stages in [firstStage, lastStage] alone when
  /// given (a render's figures: its few stages summed, not the frame's hundreds).
  std::vector<WorkSpan> workSpans(uint32_t frames, int32_t firstStage = 0, int32_t lastStage = INT32_MAX) const;
  /// The same frames' work and span summed (each frame's stages in the order first met, so
  /// the sums may differ from workSpans()' in the last bits), without per-stage lists or a
  /// sort per frame: what a run reports.
  WorkSpanTotals workSpanTotals(uint32_t frames) const;
  /// Writes every event as Chrome trace JSON ("X" complete events, microseconds). Throws
  /// std::runtime_error naming the path if the file cannot be written.
  void writeChromeTrace(const std::string& path) const;
  /// Drops every recorded event (buffers keep their capacity).
  void clear();

 private:
  struct ThreadBuffer;
  ThreadBuffer& bufferForThisThread();
  static void append(ThreadBuffer& b, ProfileEvent e);

  std::chrono::steady_clock::time_point epoch_;
  bool enabled_ = true;
  uint32_t frame_ = 0;
  uint64_t id_;                                        // distinguishes profilers in thread slots
  mutable std::mutex registry_;                        // taken once per thread, and by readers
  std::vector<std::unique_ptr<ThreadBuffer>> buffers_;
};

/// RAII zone: records [construction, destruction) on the current thread.
class ProfileZone {
 public:
  ProfileZone(Profiler& p, const char* name, int32_t stage = -1, bool serial = false)
      : p_(p), name_(name), stage_(stage), serial_(serial), begin_(p.enabled() ? p.now() : 0) {}
  ~ProfileZone() {
    if (p_.enabled()) p_.record(name_, begin_, p_.now(), stage_, serial_);
  }
  ProfileZone(const ProfileZone&) = delete;
  ProfileZone& operator=(const ProfileZone&) = delete;

 private:
  Profiler& p_;
  const char* name_;
  int32_t stage_;
  bool serial_;
  int64_t begin_;
};

}  // namespace bw
