// Times one pipeline stage and records its peak resident memory.
#pragma once

#include <chrono>
#include <string>

#include "g2p/pipeline.h"

namespace g2p::detail {

class StageClock {
 public:
  // `reset_peak`: reset the process's memory high-water mark first, so that
  // finish() reports this stage's own peak.
  StageClock(Stage stage, std::string backend, bool reset_peak);
  StageReport& report() { return report_; }
  // Wall time since construction and the peak resident memory since then.
  StageReport finish();

 private:
  std::chrono::steady_clock::time_point start_;
  StageReport report_;
};

}  // namespace g2p::detail
