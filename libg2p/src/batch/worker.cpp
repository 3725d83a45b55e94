// One asset's worker process: fork + exec of `g2p run` in its own process
// group (so a timeout or a stop reaches everything it started, and a
// terminal's Ctrl-C reaches only the batch, which decides), under a memory
// limit, with its stderr kept for the error message.
#include "batch/worker.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

namespace g2p::detail {

Result<WorkerProcess> WorkerProcess::start(const std::vector<std::string>& argv, const std::string& stderr_path,
                                           double memory_limit_gib) {
  if (argv.empty()) return Status::InvalidArgument("no program to run");
  // Everything the child needs is prepared before fork(): after it, in a
  // process that may have threads, only async-signal-safe calls are allowed.
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  rlimit limit{};
  const bool limited = memory_limit_gib > 0;
  if (limited) {
    const double bytes = std::ceil(memory_limit_gib * 1024.0 * 1024.0 * 1024.0);
    limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>(bytes);
  }
  const int err = ::open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (err < 0) return Status::IoError(stderr_path + ": cannot create: " + std::strerror(errno));
  const auto started = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(err);
    return Status::Unavailable(std::string("cannot start a worker process: ") + std::strerror(error));
  }
  if (pid == 0) {
    ::setpgid(0, 0);
    // The batch's own handlers and blocked signals must not reach the run.
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    for (int s : {SIGINT, SIGTERM, SIGPIPE, SIGHUP}) ::signal(s, SIG_DFL);
    // RLIMIT_DATA (since Linux 4.7 every private writable mapping): the
    // memory a run uses, unlike RLIMIT_AS, which address-space reservations
    // of threads and allocators would exhaust long before.
    if (limited) ::setrlimit(RLIMIT_DATA, &limit);
    const int null = ::open("/dev/null", O_RDWR);
    if (null >= 0) {
      ::dup2(null, STDIN_FILENO);
      ::dup2(null, STDOUT_FILENO);
    }
    ::dup2(err, STDERR_FILENO);
    ::execv(args[0], args.data());
    const char* why = std::strerror(errno);
    const char prefix[] = "error: cannot run the g2p tool ";
    (void)!::write(STDERR_FILENO, prefix, sizeof prefix - 1);
    (void)!::write(STDERR_FILENO, args[0], std::strlen(args[0]));
    (void)!::write(STDERR_FILENO, ": ", 2);
    (void)!::write(STDERR_FILENO, why, std::strlen(why));
    (void)!::write(STDERR_FILENO, "\n", 1);
    ::_exit(127);
  }
  ::setpgid(pid, pid);  // also here: no race with a signal sent right after start
  ::close(err);
  WorkerProcess w;
  w.pid_ = pid;
  w.started_ = started;
  return w;
}

bool WorkerProcess::poll(WorkerExit& exit) {
  int status = 0;
  rusage usage{};
  const pid_t r = ::wait4(pid_, &status, WNOHANG, &usage);
  if (r != pid_) return false;
  exit.exited = WIFEXITED(status);
  exit.code = exit.exited ? WEXITSTATUS(status) : WTERMSIG(status);
  exit.seconds = elapsed_s();
  exit.peak_rss_bytes = static_cast<std::size_t>(usage.ru_maxrss) * 1024;  // KiB on Linux
  return true;
}

void WorkerProcess::signal_group(int signal) const {
  if (pid_ > 0) ::killpg(pid_, signal);
}

double WorkerProcess::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
}

std::string signal_name(int signal) {
  switch (signal) {
    case SIGSEGV: return "SIGSEGV";
    case SIGABRT: return "SIGABRT";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    case SIGILL: return "SIGILL";
    case SIGKILL: return "SIGKILL";
    case SIGTERM: return "SIGTERM";
    case SIGINT: return "SIGINT";
    case SIGPIPE: return "SIGPIPE";
    case SIGHUP: return "SIGHUP";
    case SIGTRAP: return "SIGTRAP";
    case SIGXCPU: return "SIGXCPU";
    default: return "signal " + std::to_string(signal);
  }
}

std::string last_error_line(const std::string& stderr_text) {
  std::istringstream in(stderr_text);
  std::string last;
  for (std::string line; std::getline(in, line);)  // CLI11's trailer says nothing of the cause
    if (line.find_first_not_of(" \t\r") != std::string::npos &&
        line.rfind("Run with --help for more information.", 0) != 0)
      last = line;
  while (!last.empty() && (last.back() == '\r' || last.back() == ' ')) last.pop_back();
  for (const std::string prefix : {"g2p run: ", "error: "})
    if (last.rfind(prefix, 0) == 0) last = last.substr(prefix.size());
  return last;
}

std::string describe_failure(const WorkerExit& exit, const std::string& stderr_text, double memory_limit_gib) {
  const std::string last = last_error_line(stderr_text);
  if (exit.exited) {
    if (!last.empty()) return last;
    return "g2p run exited with status " + std::to_string(exit.code) + " and no message";
  }
  char limit[64] = "";
  if (memory_limit_gib > 0) std::snprintf(limit, sizeof limit, "%g GiB", memory_limit_gib);
  const std::string name = signal_name(exit.code);
  // An allocation refused at the limit ends as std::bad_alloc, or as an abort
  // where a library cannot report it (a thread that cannot start).
  const bool memory_words = stderr_text.find("bad_alloc") != std::string::npos ||
                            stderr_text.find("terminate called") != std::string::npos ||
                            stderr_text.find("Cannot allocate memory") != std::string::npos ||
                            stderr_text.find("out of memory") != std::string::npos;
  if (memory_limit_gib > 0 && memory_words && (exit.code == SIGABRT || exit.code == SIGSEGV || exit.code == SIGBUS))
    return std::string("out of memory: the run exceeded the ") + limit + " memory limit (ended by " + name + ")";
  if (exit.code == SIGKILL)
    return "killed (SIGKILL), most likely out of memory: the system's out-of-memory killer sends it";
  std::string message = "crashed (" + name + ")";
  if (memory_limit_gib > 0) message += std::string(" under the ") + limit + " memory limit";
  if (!last.empty()) message += ": " + last;
  return message;
}

}  // namespace g2p::detail
