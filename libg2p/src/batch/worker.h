// Private: one asset's worker process (`g2p run` as a child in its own process
// group, under a memory limit), and the words for how it ended.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <string>
#include <vector>

#include "g2p/status.h"

namespace g2p::detail {

// How a worker process ended.
struct WorkerExit {
  bool exited = false;   // exit() was called; `code` holds its status
  int code = 0;          // exit status, or the signal number when !exited
  double seconds = 0.0;  // wall-clock seconds since it started
  std::size_t peak_rss_bytes = 0;
};

class WorkerProcess {
 public:
  // Starts `argv` (argv[0] is the executable's path) in a new process group,
  // stdin and stdout on /dev/null, stderr into `stderr_path`, with a data
  // segment limit of `memory_limit_gib` (0 = none).
  static Result<WorkerProcess> start(const std::vector<std::string>& argv, const std::string& stderr_path,
                                     double memory_limit_gib);

  // Non-blocking: true once the process has ended (then `exit` is filled).
  bool poll(WorkerExit& exit);
  // Sends `signal` to the whole process group.
  void signal_group(int signal) const;
  pid_t pid() const { return pid_; }
  double elapsed_s() const;

 private:
  pid_t pid_ = -1;
  std::chrono::steady_clock::time_point started_;
};

// "SIGSEGV", "SIGKILL", ... ("signal 42" for one without a name here).
std::string signal_name(int signal);

// The last non-empty line of a worker's stderr, without the "g2p run: " and
// "error: " prefixes (the message `g2p run` gives).
std::string last_error_line(const std::string& stderr_text);

// Why a run failed, in words: g2p run's own message, "crashed (SIGSEGV)",
// "out of memory (...)", ... `memory_limit_gib` 0 = none.
std::string describe_failure(const WorkerExit& exit, const std::string& stderr_text, double memory_limit_gib);

}  // namespace g2p::detail
