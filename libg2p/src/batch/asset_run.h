// Private: one asset's run as a worker process, polled: the time limit, a
// stop, and the row it comes to (run.json read back, leftovers removed).
#pragma once

#include <filesystem>
#include <string>

#include "batch/worker.h"
#include "g2p/batch.h"

namespace g2p::detail {

// The hidden work folder in OUT: the workers' options files and stderr while they run.
constexpr const char* kBatchWorkDir = ".g2p-batch.tmp";

class AssetRun {
 public:
  // Writes the asset's options file and starts `TOOL run MODEL -o OUT/NAME ... --options FILE`.
  static Result<AssetRun> start(const BatchAsset& asset, const BatchOptions& options);

  // Non-blocking: enforces the time limit; true once the process has ended,
  // with `row` filled (status, error, results; not the key).
  bool poll(BatchRow& row);
  // SIGTERM to the process group now, SIGKILL after options.kill_grace_s.
  void stop(int signal);

 private:
  void finish(const WorkerExit& exit, BatchRow& row);

  BatchAsset asset_;
  const BatchOptions* options_ = nullptr;
  WorkerProcess process_;
  std::filesystem::path stderr_path_;
  std::filesystem::path options_path_;  // its options file (`g2p run --options`)
  double term_sent_s_ = -1.0;           // elapsed time of the SIGTERM sent, -1 = none
  bool timed_out_ = false;
  int stopped_by_ = 0;  // the batch's stop signal, when it stopped this one
};

// A whole file's bytes ("" when it cannot be read).
std::string read_text(const std::filesystem::path& path);

// UTC now, ISO 8601.
std::string utc_now();

// Whether OUT/NAME holds a whole run (its run.json), filling the row's results from it.
bool asset_output_complete(const std::string& folder, BatchRow& row);

}  // namespace g2p::detail
