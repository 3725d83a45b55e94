// One asset of a batch: `g2p run` as a worker process (worker.cpp) under the
// time limit, stopped on request, and its row: run.json read back, or the
// failure in words; what a killed run leaves in OUT is removed.
#include "batch/asset_run.h"

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

namespace g2p::detail {
namespace {

namespace fs = std::filesystem;

std::string number_text(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

// Fills the row's results from the asset's run.json; false if it is missing or malformed.
bool read_run_json(const fs::path& folder, BatchRow& row) {
  std::ifstream in(folder / "run.json");
  if (!in) return false;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("format", "") != "g2p-run") return false;
  row.parts = 0;
  row.materials.clear();
  if (j.contains("parts") && j["parts"].is_array()) {
    row.parts = j["parts"].size();
    for (const nlohmann::json& p : j["parts"]) {
      const std::string m = p.is_object() ? p.value("material", "") : "";
      if (!m.empty() && std::find(row.materials.begin(), row.materials.end(), m) == row.materials.end())
        row.materials.push_back(m);
    }
  }
  if (j.contains("object") && j["object"].is_object()) {
    row.mass_kg = j["object"].value("mass_kg", 0.0);
    row.mass_min_kg = j["object"].value("mass_min_kg", 0.0);
    row.mass_max_kg = j["object"].value("mass_max_kg", 0.0);
  }
  row.kind.clear();
  row.kind_confidence = 0.0;
  row.mass_in_kind_range.clear();
  if (j.contains("identification") && j["identification"].is_object()) {
    const nlohmann::json& id = j["identification"];
    row.kind = id.value("kind", "");
    row.kind_confidence = id.value("confidence", 0.0);
    if (id.contains("mass_in_kind_range") && id["mass_in_kind_range"].is_boolean())
      row.mass_in_kind_range = id["mass_in_kind_range"].get<bool>() ? "yes" : "no";
  }
  row.warnings.clear();
  if (j.contains("warnings") && j["warnings"].is_array())
    for (const nlohmann::json& w : j["warnings"])
      if (w.is_string()) row.warnings.push_back(w.get<std::string>());
  row.stage_seconds.clear();
  if (j.contains("stages") && j["stages"].is_array())
    for (const nlohmann::json& s : j["stages"])
      if (s.is_object() && s.contains("stage")) row.stage_seconds[s.value("stage", "")] = s.value("seconds", 0.0);
  return true;
}

}  // namespace

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buffer;
}

bool asset_output_complete(const std::string& folder, BatchRow& row) { return read_run_json(folder, row); }

Result<AssetRun> AssetRun::start(const BatchAsset& asset, const BatchOptions& options) {
  const fs::path out(options.output_dir);
  Result<RunOptions> run_options = batch_asset_options(asset, options);
  if (!run_options.ok()) return run_options.status();
  AssetRun r;
  r.asset_ = asset;
  r.options_ = &options;
  std::error_code ec;
  fs::create_directories(out / kBatchWorkDir, ec);
  if (ec) return Status::IoError((out / kBatchWorkDir).string() + ": cannot create: " + ec.message());
  r.stderr_path_ = out / kBatchWorkDir / (asset.name + ".stderr");
  r.options_path_ = out / kBatchWorkDir / (asset.name + ".options.json");
  G2P_RETURN_IF_ERROR(write_options_file(r.options_path_.string(), *run_options));
  const std::vector<std::string> argv{options.tool,
                                      "run",
                                      asset.path,
                                      "-o",
                                      (out / asset.name).string(),
                                      "--overwrite",
                                      "-q",
                                      "--options",
                                      r.options_path_.string()};
  Result<WorkerProcess> p = WorkerProcess::start(argv, r.stderr_path_.string(), options.memory_limit_gib);
  if (!p.ok()) return p.status();
  r.process_ = *p;
  return r;
}

void AssetRun::stop(int signal) {
  if (stopped_by_ != 0) return;
  stopped_by_ = signal;
  process_.signal_group(SIGTERM);
  if (term_sent_s_ < 0) term_sent_s_ = process_.elapsed_s();
}

bool AssetRun::poll(BatchRow& row) {
  WorkerExit exit;
  if (process_.poll(exit)) {
    finish(exit, row);
    return true;
  }
  const double elapsed = process_.elapsed_s();
  if (options_->timeout_s > 0 && elapsed > options_->timeout_s && term_sent_s_ < 0) {
    timed_out_ = true;
    process_.signal_group(SIGTERM);
    term_sent_s_ = elapsed;
  } else if (term_sent_s_ >= 0 && elapsed - term_sent_s_ > options_->kill_grace_s) {
    process_.signal_group(SIGKILL);
  }
  return false;
}

void AssetRun::finish(const WorkerExit& exit, BatchRow& row) {
  const fs::path out(options_->output_dir);
  const fs::path folder = out / asset_.name;
  const std::string err = read_text(stderr_path_);
  std::error_code ec;
  fs::remove(stderr_path_, ec);
  fs::remove(options_path_, ec);
  row = BatchRow{};
  row.name = asset_.name;
  row.input = asset_.path;
  row.origin = asset_.origin;
  row.exit_code = exit.exited ? exit.code : 128 + exit.code;
  row.seconds = exit.seconds;
  row.peak_rss_bytes = exit.peak_rss_bytes;
  row.finished_at = utc_now();
  const bool ran_ok = exit.exited && exit.code == 0;
  if (ran_ok && read_run_json(folder, row)) {  // done before a stop or a timeout took effect: it stands
    row.status = "ok";
    row.output = folder.string();
  } else if (stopped_by_ != 0 && !timed_out_) {
    row.status = "cancelled";
    row.error = "cancelled (" + signal_name(stopped_by_) + ")";
  } else {
    row.status = "failed";
    if (timed_out_) {
      row.error = "timed out after " + number_text(options_->timeout_s) + " s";
    } else if (ran_ok) {
      row.error = "g2p run succeeded but wrote no readable run.json in " + folder.string();
    } else {
      row.error = describe_failure(exit, err, options_->memory_limit_gib);
    }
    // An earlier output of this name belongs to other content or options.
    fs::remove_all(folder, ec);
  }
  // A killed run leaves its hidden .NAME.g2p-PID.tmp folder behind.
  const std::string tag = "." + asset_.name + ".g2p-" + std::to_string(process_.pid());
  fs::remove_all(out / (tag + ".tmp"), ec);
  fs::remove_all(out / (tag + ".old"), ec);
}

}  // namespace g2p::detail

namespace g2p {

Result<RunOptions> batch_asset_options(const BatchAsset& asset, const BatchOptions& options) {
  RunOptions run = options.run;
  if (!asset.options.empty()) {
    Result<RunOptions> own = parse_options_file(asset.options, asset.origin + ": options", run);
    if (!own.ok()) return own.status();
    run = std::move(*own);
  }
  if (options.memory_limit_gib > 0)
    run.pipeline.memory_limit_bytes = static_cast<std::size_t>(options.memory_limit_gib * 1024.0 * 1024.0 * 1024.0);
  return run;
}

Result<BatchRow> run_batch_asset(const BatchAsset& asset, const BatchOptions& options) {
  if (options.tool.empty()) return Status::InvalidArgument("run_batch_asset: no g2p tool given (BatchOptions::tool)");
  Result<detail::AssetRun> run = detail::AssetRun::start(asset, options);
  if (!run.ok()) return run.status();
  BatchRow row;
  while (!run->poll(row)) {
    if (const int stop = options.stop_requested ? options.stop_requested() : 0; stop != 0) run->stop(stop);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return row;
}

}  // namespace g2p
