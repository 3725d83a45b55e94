// run_batch: decides which assets run (resume), hands them to an executor
// (local worker processes by default, asset_run.cpp), stops on request, and
// rewrites the index after every asset. An flock on OUT/.g2p-batch.lock keeps
// a second batch off the same output.
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <deque>
#include <filesystem>
#include <map>
#include <thread>

#include "batch/asset_run.h"
#include "batch/worker.h"
#include "core/file_util.h"
#include "g2p/batch.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

constexpr const char* kLockFile = ".g2p-batch.lock";

// Removes what killed runs leave in OUT: `g2p run`'s hidden .NAME.g2p-PID.tmp
// (and .old) folders, and the batch's work folder. Only under the lock.
void remove_leftovers(const fs::path& out) {
  std::error_code ec;
  fs::remove_all(out / detail::kBatchWorkDir, ec);
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
      const std::string holder = detail::read_text(path);
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

// The default executor: `jobs` local worker processes.
class LocalExecutor : public BatchExecutor {
 public:
  explicit LocalExecutor(const BatchOptions& options) : options_(options) {}
  std::size_t capacity() const override { return static_cast<std::size_t>(options_.jobs); }
  Status submit(std::size_t ticket, const BatchAsset& asset) override {
    Result<detail::AssetRun> run = detail::AssetRun::start(asset, options_);
    if (!run.ok()) return run.status();
    running_.emplace_back(ticket, std::move(*run));
    return Status::Ok();
  }
  std::vector<std::pair<std::size_t, BatchRow>> finished() override {
    std::vector<std::pair<std::size_t, BatchRow>> done;
    for (auto it = running_.begin(); it != running_.end();) {
      BatchRow row;
      if (it->second.poll(row)) {
        done.emplace_back(it->first, std::move(row));
        it = running_.erase(it);
      } else {
        ++it;
      }
    }
    return done;
  }
  void stop(int signal) override {
    for (auto& [ticket, run] : running_) run.stop(signal);
  }

 private:
  const BatchOptions& options_;
  std::vector<std::pair<std::size_t, detail::AssetRun>> running_;
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
    fs::create_directories(out_ / detail::kBatchWorkDir, ec);
    if (ec) return Status::IoError((out_ / detail::kBatchWorkDir).string() + ": cannot create: " + ec.message());
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
    for (const BatchAsset& a : assets_) {
      Result<RunOptions> run = batch_asset_options(a, options_);
      if (!run.ok()) return Status::InvalidArgument(run.status().message());
      // Each run gets its options as a file, and a file never holds a secret.
      if (const std::vector<std::string> secret = options_file_redactions(*run); !secret.empty())
        return Status::InvalidArgument(
            a.origin + ": " + secret.front() +
            " has credentials in its URL (user:password@ or ?key=), which the options file each run reads never "
            "holds: give the API key through the environment (the api_key_env setting)");
    }
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
        row.finished_at = detail::utc_now();
        upsert(row);
        ++result_.failed;
        continue;
      }
      row.key = *key;
      const BatchRow* before = previous(a.name);
      const bool same = before != nullptr && before->key == row.key && before->input == a.path;
      const bool complete =
          same && before->status == "ok" && detail::asset_output_complete((out_ / a.name).string(), row);
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
    LocalExecutor local(options_);
    BatchExecutor& executor = options_.executor != nullptr ? *options_.executor : local;
    const std::size_t capacity = std::max<std::size_t>(1, executor.capacity());
    while (true) {
      const int stop = options_.stop_requested ? options_.stop_requested() : 0;
      if (stop != 0 && stop_signal_ == 0) {
        stop_signal_ = stop;
        executor.stop(stop);
      }
      while (stop_signal_ == 0 && !queue_.empty() && in_flight_ < capacity) {
        const std::size_t i = queue_.front();
        queue_.pop_front();
        if (Status s = executor.submit(i, assets_[i]); !s.ok()) {
          executor.stop(SIGTERM);  // nothing more can start: end what runs, keep the index
          stop_signal_ = SIGTERM;
          queue_.push_front(i);
          error_ = s;
          break;
        }
        ++in_flight_;
        report(nullptr);
      }
      for (auto& [ticket, row] : executor.finished()) G2P_RETURN_IF_ERROR(finish(ticket, std::move(row)));
      if (in_flight_ == 0 && (queue_.empty() || stop_signal_ != 0)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    for (std::size_t i : queue_) {  // never started: the batch was stopped
      BatchRow& row = result_.rows[i];
      row.status = "cancelled";
      row.error = "not started: the batch was stopped (" + detail::signal_name(stop_signal_) + ")";
      ++result_.cancelled;
    }
    result_.stop_signal = error_.ok() ? stop_signal_ : 0;
    G2P_RETURN_IF_ERROR(write_index());
    return error_;
  }

  Status finish(std::size_t i, BatchRow row) {
    if (i >= assets_.size() || in_flight_ == 0) return Status::Internal("batch executor returned an unknown asset");
    --in_flight_;
    ++finished_;
    BatchRow& kept = result_.rows[i];
    row.name = kept.name;  // as planned, whatever the executor says
    row.input = kept.input;
    row.origin = kept.origin;
    row.key = kept.key;
    if (row.status == "ok") {
      ++result_.succeeded;
    } else if (row.status == "cancelled") {
      ++result_.cancelled;
    } else {
      row.status = "failed";
      ++result_.failed;
    }
    kept = row;
    upsert(row);
    G2P_RETURN_IF_ERROR(write_index());
    report(&kept);
    return Status::Ok();
  }

  void report(const BatchRow* last) {
    if (!options_.on_progress) return;
    BatchProgress p;
    p.total = assets_.size();
    p.skipped = result_.skipped;
    p.failed = result_.failed;
    p.done = result_.succeeded + result_.failed + result_.skipped + result_.cancelled;
    p.running = in_flight_;
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
  std::size_t to_run_ = 0, finished_ = 0, in_flight_ = 0;
  int stop_signal_ = 0;
  Status error_;  // an executor that could not start an asset
};

}  // namespace

Result<BatchResult> run_batch(const std::vector<BatchAsset>& assets, const BatchOptions& options) {
  return BatchRunner(assets, options).run();
}

}  // namespace g2p
