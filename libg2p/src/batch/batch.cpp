// run_batch: the pool of worker processes over the asset list. One thread
// polls the workers (wait4 with WNOHANG), enforces the time limit (SIGTERM,
// then SIGKILL after a grace period), stops on request, reads each finished
// asset's run.json and rewrites the index after every asset. An flock on
// OUT/.g2p-batch.lock keeps a second batch off the same output.
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "batch/worker.h"
#include "core/file_util.h"
#include "g2p/batch.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

constexpr const char* kLockFile = ".g2p-batch.lock";
constexpr const char* kWorkDir = ".g2p-batch.tmp";  // the workers' stderr while they run

std::string read_text(const fs::path& path) {
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

std::string seconds_text(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", s);
  return buffer;
}

// The flags an asset's own flag replaces (CLI11 refuses a flag given twice;
// --height and --longest-side exclude each other).
std::vector<std::string> replaced_by(const std::string& flag) {
  if (flag == "--height" || flag == "--longest-side") return {"--height", "--longest-side"};
  return {flag};
}

// The batch's flags, less those the asset gives itself, then the asset's.
std::vector<std::string> merged_run_args(const std::vector<std::string>& batch, const std::vector<std::string>& own) {
  std::vector<std::string> dropped;
  for (const std::string& a : own)
    if (a.rfind("--", 0) == 0)
      for (const std::string& f : replaced_by(a.substr(0, a.find('=')))) dropped.push_back(f);
  std::vector<std::string> out;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    const std::string flag = batch[i].substr(0, batch[i].find('='));
    if (std::find(dropped.begin(), dropped.end(), flag) == dropped.end()) {
      out.push_back(batch[i]);
      continue;
    }
    // Skip the flag and its value (a following word that is not a flag).
    if (batch[i].find('=') == std::string::npos && i + 1 < batch.size() && batch[i + 1].rfind("--", 0) != 0) ++i;
  }
  out.insert(out.end(), own.begin(), own.end());
  return out;
}

// Fills the row's results from the asset's run.json; false if it is missing or malformed.
bool read_run_json(const fs::path& folder, BatchRow& row) {
  std::ifstream in(folder / "run.json");
  if (!in) return false;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("format", "") != "g2p-run") return false;
  row.parts = j.contains("parts") && j["parts"].is_array() ? j["parts"].size() : 0;
  row.materials.clear();
  if (j.contains("parts") && j["parts"].is_array())
    for (const nlohmann::json& p : j["parts"]) {
      const std::string m = p.is_object() ? p.value("material", "") : "";
      if (!m.empty() && std::find(row.materials.begin(), row.materials.end(), m) == row.materials.end())
        row.materials.push_back(m);
    }
  if (j.contains("object") && j["object"].is_object()) {
    row.mass_kg = j["object"].value("mass_kg", 0.0);
    row.mass_min_kg = j["object"].value("mass_min_kg", 0.0);
    row.mass_max_kg = j["object"].value("mass_max_kg", 0.0);
  }
  row.stage_seconds.clear();
  if (j.contains("stages") && j["stages"].is_array())
    for (const nlohmann::json& s : j["stages"])
      if (s.is_object() && s.contains("stage")) row.stage_seconds[s.value("stage", "")] = s.value("seconds", 0.0);
  return true;
}

// Removes what killed runs leave in OUT: `g2p run`'s hidden .NAME.g2p-PID.tmp
// (and .old) folders, and the batch's work folder. Only under the lock.
void remove_leftovers(const fs::path& out) {
  std::error_code ec;
  fs::remove_all(out / kWorkDir, ec);
  std::vector<fs::path> stale;
  for (auto it = fs::directory_iterator(out, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const bool temp = name.size() > 5 &&
                      (name.compare(name.size() - 4, 4, ".tmp") == 0 || name.compare(name.size() - 4, 4, ".old") == 0);
    if (!name.empty() && name[0] == '.' && name.find(".g2p-") != std::string::npos && temp) stale.push_back(it->path());
  }
  for (const fs::path& p : stale) fs::remove_all(p, ec);
}

// An exclusive flock on OUT/.g2p-batch.lock, held while the batch runs.
class OutputLock {
 public:
  ~OutputLock() {
    if (fd_ >= 0) ::close(fd_);  // releases the lock
  }
  Status acquire(const fs::path& out) {
    const fs::path path = out / kLockFile;
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) return Status::IoError(path.string() + ": cannot open: " + std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const std::string holder = read_text(path);
      return Status::Unavailable(out.string() + ": another g2p batch" +
                                 (holder.empty() ? std::string() : " (pid " + holder + ")") +
                                 " is writing to this folder; wait for it to finish or choose another output");
    }
    const std::string pid = std::to_string(::getpid());
    if (::ftruncate(fd_, 0) == 0) (void)!::pwrite(fd_, pid.data(), pid.size(), 0);
    return Status::Ok();
  }

 private:
  int fd_ = -1;
};

// One running asset.
struct Running {
  std::size_t index = 0;  // into the asset list
  detail::WorkerProcess process;
  fs::path stderr_path;
  double term_sent_s = -1.0;  // elapsed time of the SIGTERM sent, -1 = none
  bool timed_out = false;
  int stopped_by = 0;  // the batch's stop signal, when it stopped this one
};

class BatchRunner {
 public:
  BatchRunner(const std::vector<BatchAsset>& assets, const BatchOptions& options)
      : assets_(assets), options_(options), out_(options.output_dir), started_(std::chrono::steady_clock::now()) {}

  Result<BatchResult> run() {
    G2P_RETURN_IF_ERROR(check());
    G2P_RETURN_IF_ERROR(detail::ensure_directory(out_.string()));
    OutputLock lock;
    G2P_RETURN_IF_ERROR(lock.acquire(out_));
    remove_leftovers(out_);
    Result<std::vector<BatchRow>> index = read_batch_index(out_.string());
    if (!index.ok()) return index.status();
    index_ = std::move(*index);
    std::error_code ec;
    fs::create_directories(out_ / kWorkDir, ec);
    if (ec) return Status::IoError((out_ / kWorkDir).string() + ": cannot create: " + ec.message());
    plan();
    report(nullptr);
    Status s = loop();
    remove_leftovers(out_);
    if (!s.ok()) return s;
    return std::move(result_);
  }

 private:
  Status check() const {
    if (options_.tool.empty()) return Status::InvalidArgument("run_batch: no g2p tool given (BatchOptions::tool)");
    if (::access(options_.tool.c_str(), X_OK) != 0)
      return Status::NotFound(options_.tool + ": the g2p tool is not an executable file");
    if (options_.output_dir.empty()) return Status::InvalidArgument("run_batch: no output folder given");
    if (options_.jobs < 1) return Status::InvalidArgument("--jobs must be 1 or more");
    if (!(options_.timeout_s >= 0)) return Status::InvalidArgument("--timeout must be 0 (none) or more seconds");
    if (!(options_.memory_limit_gib >= 0))
      return Status::InvalidArgument("--memory-limit must be 0 (none) or more GiB");
    for (const BatchAsset& a : assets_)
      if (a.name.empty() || a.name[0] == '.' || a.name.find('/') != std::string::npos)
        return Status::InvalidArgument(a.origin + ": no usable folder name (name the assets with name_batch_assets)");
    return Status::Ok();
  }

  const BatchRow* previous(const std::string& name) const {
    for (const BatchRow& r : index_)
      if (r.name == name) return &r;
    return nullptr;
  }

  void upsert(const BatchRow& row) {
    for (BatchRow& r : index_)
      if (r.name == row.name) {
        r = row;
        return;
      }
    index_.push_back(row);
  }

  // The index in this batch's list order, then the rows of earlier batches.
  Status write_index() {
    std::map<std::string, std::size_t> position;
    for (std::size_t i = 0; i < assets_.size(); ++i) position.emplace(assets_[i].name, i);
    auto rank = [&](const BatchRow& r) {
      auto it = position.find(r.name);
      return it == position.end() ? assets_.size() : it->second;
    };
    std::stable_sort(index_.begin(), index_.end(),
                     [&](const BatchRow& a, const BatchRow& b) { return rank(a) < rank(b); });
    return write_batch_index(out_.string(), index_);
  }

  // Which assets run: new ones, changed ones (another key), interrupted ones,
  // ok ones whose output is gone, and with retry_failed the failed ones.
  void plan() {
    result_.rows.resize(assets_.size());
    for (std::size_t i = 0; i < assets_.size(); ++i) {
      const BatchAsset& a = assets_[i];
      BatchRow& row = result_.rows[i];
      row.name = a.name;
      row.input = a.path;
      row.origin = a.origin;
      Result<std::string> key = batch_asset_key(a, options_);
      if (!key.ok()) {  // unreadable: a failure of its own, like any other
        row.status = "failed";
        row.error = key.status().message();
        row.finished_at = utc_now();
        upsert(row);
        ++result_.failed;
        continue;
      }
      row.key = *key;
      const BatchRow* before = previous(a.name);
      const bool same = before != nullptr && before->key == row.key && before->input == a.path;
      const bool complete = same && before->status == "ok" && read_run_json(out_ / a.name, row);
      const bool kept_failure = same && before->status == "failed" && !options_.retry_failed;
      if (complete || kept_failure) {
        row = *before;
        row.origin = a.origin;
        ++result_.skipped;
        continue;
      }
      queue_.push_back(i);
    }
    to_run_ = queue_.size();
  }

  Status loop() {
    std::vector<Running> running;
    while (true) {
      const int stop = options_.stop_requested ? options_.stop_requested() : 0;
      if (stop != 0 && stop_signal_ == 0) {
        stop_signal_ = stop;
        for (Running& r : running) {
          r.stopped_by = stop;
          r.process.signal_group(SIGTERM);
          r.term_sent_s = r.process.elapsed_s();
        }
      }
      while (stop_signal_ == 0 && !queue_.empty() && static_cast<int>(running.size()) < options_.jobs) {
        const std::size_t i = queue_.front();
        queue_.pop_front();
        Result<Running> started = start(i);
        if (!started.ok()) return started.status();  // fork failed: nothing more can start
        running.push_back(std::move(*started));
        report(nullptr);
      }
      for (auto it = running.begin(); it != running.end();) {
        detail::WorkerExit exit;
        if (it->process.poll(exit)) {
          G2P_RETURN_IF_ERROR(finish(*it, exit));
          it = running.erase(it);
          continue;
        }
        const double elapsed = it->process.elapsed_s();
        if (options_.timeout_s > 0 && elapsed > options_.timeout_s && it->term_sent_s < 0) {
          it->timed_out = true;
          it->process.signal_group(SIGTERM);
          it->term_sent_s = elapsed;
        } else if (it->term_sent_s >= 0 && elapsed - it->term_sent_s > options_.kill_grace_s) {
          it->process.signal_group(SIGKILL);
        }
        ++it;
      }
      if (running.empty() && (queue_.empty() || stop_signal_ != 0)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    for (std::size_t i : queue_) {  // never started: the batch was stopped
      BatchRow& row = result_.rows[i];
      row.status = "cancelled";
      row.error = "not started: the batch was stopped (" + detail::signal_name(stop_signal_) + ")";
      ++result_.cancelled;
    }
    result_.stop_signal = stop_signal_;
    return write_index();
  }

  Result<Running> start(std::size_t i) {
    const BatchAsset& a = assets_[i];
    std::vector<std::string> argv{options_.tool, "run", a.path, "-o", (out_ / a.name).string(), "--overwrite", "-q"};
    std::vector<std::string> flags = merged_run_args(options_.run_args, a.run_args);
    if (options_.memory_limit_gib > 0)
      flags = merged_run_args(flags, {"--memory-limit", seconds_text(options_.memory_limit_gib)});
    argv.insert(argv.end(), flags.begin(), flags.end());
    Running r;
    r.index = i;
    r.stderr_path = out_ / kWorkDir / (a.name + ".stderr");
    Result<detail::WorkerProcess> p =
        detail::WorkerProcess::start(argv, r.stderr_path.string(), options_.memory_limit_gib);
    if (!p.ok()) return p.status();
    r.process = *p;
    return r;
  }

  Status finish(const Running& r, const detail::WorkerExit& exit) {
    const BatchAsset& a = assets_[r.index];
    BatchRow& row = result_.rows[r.index];
    const fs::path folder = out_ / a.name;
    const std::string err = read_text(r.stderr_path);
    std::error_code ec;
    fs::remove(r.stderr_path, ec);
    row.exit_code = exit.exited ? exit.code : 128 + exit.code;
    row.seconds = exit.seconds;
    row.peak_rss_bytes = exit.peak_rss_bytes;
    row.finished_at = utc_now();
    row.error.clear();
    const bool ran_ok = exit.exited && exit.code == 0;
    if (ran_ok && read_run_json(folder, row)) {  // done before a stop or a timeout took effect: it stands
      row.status = "ok";
      row.output = folder.string();
      ++result_.succeeded;
    } else if (r.stopped_by != 0 && !r.timed_out) {
      row.status = "cancelled";
      row.error = "cancelled (" + detail::signal_name(r.stopped_by) + ")";
      ++result_.cancelled;
    } else {
      row.status = "failed";
      row.output.clear();
      row.parts = 0;
      row.materials.clear();
      row.mass_kg = row.mass_min_kg = row.mass_max_kg = 0.0;
      row.stage_seconds.clear();
      if (r.timed_out) {
        row.error = "timed out after " + seconds_text(options_.timeout_s) + " s";
      } else if (ran_ok) {
        row.error = "g2p run succeeded but wrote no readable run.json in " + folder.string();
      } else {
        row.error = detail::describe_failure(exit, err, options_.memory_limit_gib);
      }
      // An earlier output of this name belongs to other content or options.
      fs::remove_all(folder, ec);
      ++result_.failed;
    }
    // A killed run leaves its hidden .NAME.g2p-PID.tmp folder behind.
    const std::string tag = "." + a.name + ".g2p-" + std::to_string(r.process.pid());
    fs::remove_all(out_ / (tag + ".tmp"), ec);
    fs::remove_all(out_ / (tag + ".old"), ec);
    ++finished_;
    upsert(row);
    G2P_RETURN_IF_ERROR(write_index());
    report(&row);
    return Status::Ok();
  }

  void report(const BatchRow* last) {
    if (!options_.on_progress) return;
    BatchProgress p;
    p.total = assets_.size();
    p.skipped = result_.skipped;
    p.failed = result_.failed;
    p.done = result_.succeeded + result_.failed + result_.skipped + result_.cancelled;
    p.running = to_run_ - finished_ - queue_.size();
    p.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    if (finished_ > 0)
      p.eta_s = p.elapsed_s / static_cast<double>(finished_) * static_cast<double>(to_run_ - finished_);
    if (last != nullptr)
      p.last = last->name + ": " + last->status + (last->error.empty() ? std::string() : ": " + last->error);
    options_.on_progress(p);
  }

  const std::vector<BatchAsset>& assets_;
  const BatchOptions& options_;
  const fs::path out_;
  const std::chrono::steady_clock::time_point started_;
  std::vector<BatchRow> index_;  // the whole index: this batch's rows and earlier ones
  BatchResult result_;
  std::deque<std::size_t> queue_;
  std::size_t to_run_ = 0, finished_ = 0;
  int stop_signal_ = 0;
};

}  // namespace

Result<BatchResult> run_batch(const std::vector<BatchAsset>& assets, const BatchOptions& options) {
  return BatchRunner(assets, options).run();
}

}  // namespace g2p
