// Batch: many models through the whole pipeline, one isolated process each.
//
// The asset list comes from folders, globs, files or a manifest (CSV or JSON
// Lines, one model per row with its own import options). Every asset runs as
// a child process `g2p run MODEL -o OUT/NAME ...` under a time and a memory
// limit, so a crash, hang or out-of-memory in one model is recorded with its
// cause and the batch goes on. OUT/index.json and OUT/index.csv hold one row
// per asset (status, error, parts, materials, mass, seconds, peak memory) and
// are replaced atomically after every asset, so an interruption leaves a
// valid index. A rerun skips the assets whose content hash (the model file,
// its companions and the options) is unchanged. docs/batch.md.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "g2p/options_file.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// One model of a batch.
struct BatchAsset {
  std::string path;  // the model file
  std::string name;  // its subfolder of OUT; "" = the file's stem (made unique by batch_assets)
  // Its own options over the batch's: an options file's keys (g2p/options_file.h),
  // {"import": {"unit_scale": 0.01}}; "" = the batch's. A manifest row's columns.
  std::string options;
  std::string origin;  // where it was listed: "assets.csv:4", or the path itself
};

// Per-asset columns a manifest may have besides `path`, each an option of
// that asset (as the `g2p run` flag of that name with '_' as '-'): name,
// unit, up, segmenter, height, longest_side, object (what the object is, in
// words). A JSON Lines row may also have "options": any keys of an options
// file (g2p/options_file.h), under the columns.
G2P_API const std::vector<std::string>& batch_manifest_columns();

// The assets of a manifest: CSV with a header row (`path` required, then any
// of batch_manifest_columns()) or JSON Lines (one object per line, same keys;
// .jsonl or .ndjson). Blank lines and lines starting with '#' are skipped.
// Relative paths are relative to the manifest's folder. An error names the
// file and line ("assets.csv:7: height 'tall' is not a number").
G2P_API Result<std::vector<BatchAsset>> read_batch_manifest(const std::string& path);

// The assets of command-line inputs: a folder gives every model file in it and
// below it whose format is read (is_supported_extension), in path order; a
// pattern with * ? or [ gives every file it matches (a pattern that matches
// nothing is an error); anything else is taken as a model file, even one that
// does not exist or has an unsupported format (its run then fails and says so).
G2P_API Result<std::vector<BatchAsset>> list_batch_inputs(const std::vector<std::string>& inputs);

// Gives every asset a unique folder name: the given name or the file's stem,
// with characters other than letters, digits, '.', '_', '-' replaced by '_',
// and "-2", "-3"... for repeats in list order. Two assets given the same
// explicit name are an error naming both origins.
G2P_API Status name_batch_assets(std::vector<BatchAsset>& assets);

// Progress after each asset that finishes (and once at the start).
struct BatchProgress {
  std::size_t total = 0;    // assets in the batch
  std::size_t done = 0;     // finished in this run (ok or failed) plus skipped
  std::size_t failed = 0;   // failed in this run
  std::size_t skipped = 0;  // unchanged since an earlier run, not run again
  std::size_t running = 0;  // worker processes now running
  double elapsed_s = 0.0;   // since the batch started
  double eta_s = -1.0;      // estimated seconds left; -1 = not known yet
  std::string last;         // "NAME: ok" or "NAME: failed: MESSAGE" of the asset that just finished
};

class BatchExecutor;

struct BatchOptions {
  std::string tool;               // the g2p executable; each asset runs `TOOL run MODEL -o OUT/NAME ...` (required)
  std::string output_dir;         // OUT: a subfolder per asset, index.json, index.csv (made if missing)
  int jobs = 1;                   // worker processes at a time (>= 1)
  double timeout_s = 0.0;         // wall-clock limit per asset, seconds; 0 = none
  double memory_limit_gib = 0.0;  // per asset, GiB (the data segment limit, and `g2p run --memory-limit`); 0 = none
  double kill_grace_s = 5.0;      // seconds between SIGTERM and SIGKILL for a stopped or timed-out asset
  // Every asset's options (each asset's own over them); written for each
  // asset as OUT/.g2p-batch.tmp/NAME.options.json for its `g2p run --options`.
  RunOptions run;
  bool retry_failed = false;  // also rerun the assets the index records as failed with the same hash
  // Polled about every 50 ms: a nonzero return (the signal number, SIGINT or
  // SIGTERM) stops the batch: no asset starts, the running ones are sent
  // SIGTERM (their output is not written) and the index is written.
  std::function<int()> stop_requested;
  std::function<void(const BatchProgress&)> on_progress;
  // Where the assets run; null = local worker processes, `jobs` at a time.
  // A cluster's executor (the Python module's Dask one) runs each asset as
  // run_batch_asset on a machine that sees the same paths.
  BatchExecutor* executor = nullptr;
};

// One row of the index: one asset's latest outcome.
struct BatchRow {
  std::string name;    // subfolder of OUT
  std::string input;   // the model file
  std::string origin;  // where it was listed (manifest line)
  std::string key;     // content hash of the model file, its companions and the options
  std::string status;  // "ok", "failed" or "cancelled" (stopped by SIGINT/SIGTERM; runs again next time)
  std::string error;   // why it failed: g2p run's message, "crashed (SIGSEGV)", "timed out after 60 s", ...
  int exit_code = 0;   // g2p run's exit status; 128 + N when signal N ended it
  std::size_t parts = 0;
  std::vector<std::string> materials;  // one per class present, in part order
  double mass_kg = 0.0, mass_min_kg = 0.0, mass_max_kg = 0.0;
  std::string kind;  // what the object was identified as ("unknown"; "" when no run.json says)
  double kind_confidence = 0.0;
  std::string mass_in_kind_range;               // "yes", "no", or "" (unknown kind): the kind's mass range as a check
  double seconds = 0.0;                         // wall-clock seconds of the asset's process
  std::map<std::string, double> stage_seconds;  // "render" -> seconds, from run.json
  std::size_t peak_rss_bytes = 0;               // the process's peak resident memory
  // What the run warns about (run.json's warnings): a part whose volume
  // disagrees with the input's, a mass outside the kind's range, ...
  std::vector<std::string> warnings;
  std::string output;       // OUT/NAME when ok, else ""
  std::string finished_at;  // UTC, ISO 8601
};

struct BatchResult {
  std::vector<BatchRow> rows;  // one per asset of this batch, in list order (skipped ones as the index had them)
  std::size_t succeeded = 0;   // ran and ok
  std::size_t failed = 0;      // ran and failed
  std::size_t skipped = 0;     // unchanged, not run
  std::size_t cancelled = 0;   // stopped by a signal, or never started because of one
  int stop_signal = 0;         // the signal that stopped the batch, 0 if none
};

// The options one asset runs with: options.run, the asset's own over them,
// and options.memory_limit_gib as the run's memory limit. An error names the
// asset's origin.
G2P_API Result<RunOptions> batch_asset_options(const BatchAsset& asset, const BatchOptions& options);

// Runs one asset where a batch would: `TOOL run MODEL -o OUT/NAME --overwrite -q --options FILE`
// as a child process in its own process group, under options.timeout_s and
// options.memory_limit_gib, stopped (SIGTERM, then SIGKILL) when
// options.stop_requested says so. Blocks until it ends; the row says how
// (key left empty). No lock, no index: run_batch's part, or a cluster
// worker's. Fails only when no process can start.
G2P_API Result<BatchRow> run_batch_asset(const BatchAsset& asset, const BatchOptions& options);

// Where run_batch runs the assets it decided to run. run_batch calls it from
// one thread: submit() while fewer than capacity() are in flight, finished()
// about every 20 ms, stop() once when the batch is stopped (then finished()
// until every submitted asset is back, as "cancelled" or whatever it came to).
class G2P_API BatchExecutor {
 public:
  virtual ~BatchExecutor() = default;
  virtual std::size_t capacity() const = 0;
  // Starts asset `ticket` (its row comes back from finished() with the same ticket).
  virtual Status submit(std::size_t ticket, const BatchAsset& asset) = 0;
  virtual std::vector<std::pair<std::size_t, BatchRow>> finished() = 0;
  virtual void stop(int signal) = 0;
};

// The content hash that decides whether an asset runs again: the model file's
// bytes, those of its companions (files of the same stem beside it: .mtl,
// .bin), the g2p version and its options file (batch_asset_options). 16 hex digits.
G2P_API Result<std::string> batch_asset_key(const BatchAsset& asset, const BatchOptions& options);

// Runs the assets (named by name_batch_assets) into options.output_dir. Fails
// only when nothing can start: no tool, an output that is not a folder, or
// another batch writing to the same output (an flock on OUT/.g2p-batch.lock);
// each asset's failure is a row.
G2P_API Result<BatchResult> run_batch(const std::vector<BatchAsset>& assets, const BatchOptions& options);

// The index as written: OUT/index.json (rows by name). A missing index is an
// empty one; a malformed one is an error naming the file.
G2P_API Result<std::vector<BatchRow>> read_batch_index(const std::string& output_dir);
G2P_API Status write_batch_index(const std::string& output_dir, const std::vector<BatchRow>& rows);

}  // namespace g2p
