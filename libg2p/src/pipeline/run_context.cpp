// Stage names, progress reports with cancellation, and the per-stage clock
// (wall time and peak resident memory).
#include "pipeline/stage_clock.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>

#include "g2p/pipeline.h"

namespace g2p {

const char* to_string(Stage stage) {
  switch (stage) {
    case Stage::kLoad: return "load";
    case Stage::kRender: return "render";
    case Stage::kIdentify: return "identify";
    case Stage::kSegment: return "segment";
    case Stage::kProject: return "project";
    case Stage::kRefine: return "refine";
    case Stage::kComplete: return "complete";
    case Stage::kProperties: return "properties";
    case Stage::kDecompose: return "decompose";
    case Stage::kExport: return "export";
  }
  return "unknown";
}

namespace {

// Share of a typical run's time per stage (measured on the shared assets,
// docs/performance.md); only shapes the overall progress fraction.
constexpr double kStageWeight[kNumStages] = {0.08, 0.20, 0.02, 0.06, 0.10, 0.04, 0.36, 0.06, 0.06, 0.04};

}  // namespace

Status RunContext::report(Stage stage, double stage_fraction, const std::string& message) {
  if (on_progress_) {
    Progress p;
    p.stage = stage;
    p.stage_fraction = std::clamp(stage_fraction, 0.0, 1.0);
    double before = 0.0, total = 0.0;
    for (int s = 0; s < kNumStages; ++s) {
      total += kStageWeight[s];
      if (s < static_cast<int>(stage)) before += kStageWeight[s];
    }
    p.overall = (before + p.stage_fraction * kStageWeight[static_cast<int>(stage)]) / total;
    p.message = message;
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      on_progress_(p);
    } catch (const std::exception& e) {  // no exception crosses the API: a throwing callback cancels
      cancel();
      return Status::Cancelled(std::string("the progress callback threw: ") + e.what());
    } catch (...) {
      cancel();
      return Status::Cancelled("the progress callback threw");
    }
  }
  if (cancelled()) return Status::Cancelled(std::string("cancelled during ") + to_string(stage));
  return Status::Ok();
}

namespace detail {

namespace {

// VmHWM (peak resident set) from /proc/self/status, in bytes; 0 where unknown.
std::size_t read_vm_hwm() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) {
      unsigned long long kb = 0;
      if (std::sscanf(line.c_str() + 6, "%llu", &kb) == 1) return static_cast<std::size_t>(kb) * 1024;
    }
  return 0;
}

// Resets the high-water mark to the current resident set (Linux >= 4.0).
bool reset_vm_hwm() {
  std::ofstream out("/proc/self/clear_refs");
  if (!out) return false;
  out << "5";
  out.flush();
  return static_cast<bool>(out);
}

}  // namespace

StageClock::StageClock(Stage stage, std::string backend, bool reset_peak) : start_(std::chrono::steady_clock::now()) {
  report_.stage = stage;
  report_.backend = std::move(backend);
  if (reset_peak) reset_vm_hwm();
}

StageReport StageClock::finish() {
  report_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  report_.peak_rss_bytes = read_vm_hwm();
  return report_;
}

}  // namespace detail
}  // namespace g2p
