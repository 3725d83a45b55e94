// assimp's parser in a child process (scene_reader.h).
//
// The child is a fork of the caller: it parses, encodes the scene and writes
// one message to a pipe: a kind byte ('S' scene, 'E' assimp's error, 'M' out
// of memory) and its payload. The parent reads to the end and waits for the
// child. A child that ends any other way crashed or was stopped; a handler
// installed in the child notes the signal and the shared library it faulted
// in, in memory shared with the parent, before the signal takes its course.
#include "scene_reader.h"

#include <assimp/postprocess.h>
#include <dlfcn.h>
#include <execinfo.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <ucontext.h>
#include <unistd.h>

#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <new>

namespace g2p::detail {
namespace {

// Where the child noted its crash (shared with the parent).
struct CrashNote {
  int signal;
  char library[120];
};

CrashNote* g_note = nullptr;  // the child's pointer to the shared note

const char* base_name(const char* path) {
  const char* slash = std::strrchr(path, '/');
  return slash != nullptr ? slash + 1 : path;
}

bool is_runtime_library(const char* name) {
  for (const char* prefix : {"libc.", "libc-", "libstdc++", "libgcc", "libpthread", "libm.", "ld-linux"})
    if (std::strncmp(name, prefix, std::strlen(prefix)) == 0) return true;
  return false;
}

// The faulting instruction's address, from the signal's context; for a call
// through a null pointer (the address is 0), the return address the call pushed.
void* fault_address(void* context) {
#if defined(__x86_64__)
  const auto* uc = static_cast<const ucontext_t*>(context);
  auto pc = static_cast<std::uintptr_t>(uc->uc_mcontext.gregs[REG_RIP]);
  if (pc == 0) pc = *reinterpret_cast<const std::uintptr_t*>(uc->uc_mcontext.gregs[REG_RSP]);
  return reinterpret_cast<void*>(pc);
#elif defined(__aarch64__)
  const auto* uc = static_cast<const ucontext_t*>(context);
  return reinterpret_cast<void*>(uc->uc_mcontext.pc != 0 ? uc->uc_mcontext.pc : uc->uc_mcontext.regs[30]);
#else
  (void)context;
  return nullptr;
#endif
}

// Notes `address`'s library unless it is the C or C++ runtime; true if noted.
bool note_library(void* address) {
  Dl_info info;
  if (address == nullptr || dladdr(address, &info) == 0 || info.dli_fname == nullptr) return false;
  const char* name = base_name(info.dli_fname);
  if (is_runtime_library(name)) return false;
  std::strncpy(g_note->library, name, sizeof g_note->library - 1);
  return true;
}

// In the child: names the library that faulted: the faulting address's, or
// (for an abort, raised inside the C library) the first caller on the stack
// outside the runtime (frame 0 is this handler, frame 1 the signal trampoline).
void on_fatal_signal(int signo, siginfo_t*, void* context) {
  if (g_note != nullptr) {
    g_note->signal = signo;
    if (!note_library(fault_address(context))) {
      void* frames[32];
      const int n = backtrace(frames, 32);
      for (int i = 2; i < n && !note_library(frames[i]); ++i) {
      }
    }
  }
  // SA_RESETHAND restored the default action: re-raising ends the child with
  // this signal, so the parent sees how it died.
  raise(signo);
}

bool write_all(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

// Whether a vertex position is NaN or infinite. JoinIdenticalVertices would
// merge such a vertex into another one (its spatial sort orders NaN anywhere),
// so the importer's check never saw it and the face silently changed shape;
// unjoined, the importer refuses it (or drops its faces with --lenient).
bool has_non_finite_position(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes && scene.mMeshes != nullptr; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    if (mesh == nullptr || mesh->mVertices == nullptr) continue;
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return true;
    }
  }
  return false;
}

// assimp 5.2's JoinIdenticalVertices compares no vertex colours (fixed after
// 5.2 by assimp pull request 4872) and would merge vertices that differ only
// in colour: a scene with colours is read without it, and the importer joins
// equal vertices itself, colours included (assimp_import.cpp).
const aiScene* read_in(Assimp::Importer& importer, const SceneSource& source, unsigned post_process) {
  const unsigned join = post_process & aiProcess_JoinIdenticalVertices;
  const unsigned first = post_process & ~join;
  const aiScene* scene = source.data != nullptr
                             ? importer.ReadFileFromMemory(source.data, source.size, first, source.hint.c_str())
                             : importer.ReadFile(source.path, first);
  if (scene == nullptr || join == 0 || has_vertex_colors(*scene) || has_non_finite_position(*scene)) return scene;
  return importer.ApplyPostProcessing(join);
}

}  // namespace

bool has_vertex_colors(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes && scene.mMeshes != nullptr; ++m)
    if (scene.mMeshes[m] != nullptr && scene.mMeshes[m]->mColors[0] != nullptr) return true;
  return false;
}

namespace {

std::string assimp_error(const Assimp::Importer& importer) {
  std::string e = importer.GetErrorString();
  while (!e.empty() && std::isspace(static_cast<unsigned char>(e.back()))) e.pop_back();
  return e.empty() ? "the file could not be parsed" : e;
}

[[noreturn]] void child_main(int fd, const SceneSource& source, unsigned post_process) {
  prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the caller
  struct sigaction sa {};
  sa.sa_sigaction = on_fatal_signal;
  sa.sa_flags = SA_SIGINFO | SA_RESETHAND;
  sigemptyset(&sa.sa_mask);
  for (int s : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) sigaction(s, &sa, nullptr);

  // The message: 'S', the scene's size (8 bytes) and its bytes, streamed as
  // they are encoded; or 'E' and assimp's error; or 'M' (out of memory).
  bool written = true;
  const SceneSink to_pipe = [&](const char* p, std::size_t n) { written = written && write_all(fd, p, n); };
  std::string message;
  try {
    Assimp::Importer importer;
    const aiScene* scene = read_in(importer, source, post_process);
    if (scene != nullptr) {
      const std::uint64_t size = encode_scene(*scene, nullptr);
      char head[1 + sizeof size] = {'S'};
      std::memcpy(head + 1, &size, sizeof size);
      written = write_all(fd, head, sizeof head);
      encode_scene(*scene, &to_pipe);
      _exit(written ? 0 : 1);
    }
    message = "E" + assimp_error(importer);
  } catch (const std::bad_alloc&) {
    message = "M";
  } catch (const std::exception& e) {
    message = std::string("E") + e.what();
  }
  _exit(write_all(fd, message.data(), message.size()) ? 0 : 1);
}

std::string signal_name(int signo) {
  switch (signo) {
    case SIGSEGV: return "segmentation fault";
    case SIGBUS: return "bus error";
    case SIGFPE: return "arithmetic exception";
    case SIGILL: return "illegal instruction";
    case SIGABRT: return "abort";
    case SIGKILL: return "SIGKILL";
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    default: return "signal " + std::to_string(signo);
  }
}

// Why a child that sent no complete message ended.
Status child_failure(int wait_status, const CrashNote& note) {
  if (WIFSIGNALED(wait_status)) {
    const int signo = WTERMSIG(wait_status);
    if (signo == SIGINT || signo == SIGTERM || signo == SIGHUP || signo == SIGQUIT)
      return Status::Cancelled("the model reader was stopped (" + signal_name(signo) + ")");
    if (signo == SIGKILL)
      return Status::OutOfMemory("the model reader was killed (SIGKILL), most likely by the system for lack of memory");
    std::string where = note.signal == signo && note.library[0] != '\0' ? std::string(" in ") + note.library : "";
    return Status::ParseError("assimp, the model reader, crashed on this file (" + signal_name(signo) + where +
                              "): the file is probably malformed. It was read in a separate process, so nothing "
                              "else was affected");
  }
  const int code = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1;
  return Status::Internal("the model reader ended without a result (exit status " + std::to_string(code) + ")");
}

// How long the child may parse: G2P_READ_TIMEOUT (seconds) if set, else 120 s
// plus 2 s per MB of input (assimp reads tens of MB a second; a loop on a
// malformed file would otherwise hang the caller).
double read_time_limit_s(const SceneSource& source) {
  if (const char* env = std::getenv("G2P_READ_TIMEOUT")) {
    char* end = nullptr;
    const double v = std::strtod(env, &end);
    if (end != env && *end == '\0' && v > 0.0 && v < 1e7) return v;
  }
  std::error_code ec;
  const std::uintmax_t bytes = source.data != nullptr ? source.size : std::filesystem::file_size(source.path, ec);
  return 120.0 + 2.0 * static_cast<double>(ec ? 0 : bytes) / 1e6;
}

}  // namespace

Result<ParsedScene> parse_scene(const SceneSource& source, unsigned post_process, bool isolate,
                                std::vector<std::string>& warnings) {
  ParsedScene parsed;
  int fds[2] = {-1, -1};
  void* shared = MAP_FAILED;
  pid_t pid = -1;
  std::string fallback;
  if (isolate) {
    shared = mmap(nullptr, sizeof(CrashNote), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (shared == MAP_FAILED || pipe2(fds, O_CLOEXEC) != 0) {
      fallback = std::strerror(errno);
    } else {
      std::memset(shared, 0, sizeof(CrashNote));
      // The crash handler's backtrace() loads the unwinder on first use: load
      // it here, once, so no child pays for it (or does it inside a handler).
      static const int unwinder_loaded = [] {
        void* frame[1];
        return backtrace(frame, 1);
      }();
      (void)unwinder_loaded;
      fcntl(fds[1], F_SETPIPE_SZ, 1 << 20);  // fewer switches for large scenes; best effort
      pid = fork();
      if (pid < 0) fallback = std::strerror(errno);
    }
  }
  if (pid == 0) {
    close(fds[0]);
    g_note = static_cast<CrashNote*>(shared);
    child_main(fds[1], source, post_process);
  }
  if (pid < 0) {
    if (fds[0] >= 0) close(fds[0]), close(fds[1]);
    if (shared != MAP_FAILED) munmap(shared, sizeof(CrashNote));
    if (isolate)
      warnings.push_back("could not start a separate process for the model reader (" + fallback +
                         "); the file was read in this process");
    parsed.importer_ = std::make_unique<Assimp::Importer>();
    if (read_in(*parsed.importer_, source, post_process) == nullptr)
      return Status::ParseError(assimp_error(*parsed.importer_));
    return parsed;
  }

  close(fds[1]);
  // The reply: a kind byte, then for a scene its size and bytes (read
  // straight into a buffer of that size), else a message to the end.
  std::string message;
  bool out_of_memory = false;
  const double limit_s = read_time_limit_s(source);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  bool timed_out = false;
  auto read_some = [&](char* p, std::size_t n) -> std::size_t {
    std::size_t got = 0;
    while (got < n && !timed_out) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      pollfd pfd{fds[0], POLLIN, 0};
      const int ready =
          left.count() > 0 ? poll(&pfd, 1, static_cast<int>(std::min<long long>(left.count(), 60'000))) : 0;
      if (ready < 0 && errno == EINTR) continue;
      if (ready == 0) {
        if (std::chrono::steady_clock::now() < deadline) continue;
        timed_out = true;
        kill(pid, SIGKILL);
        break;
      }
      const ssize_t r = read(fds[0], p + got, n - got);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) break;
      got += static_cast<std::size_t>(r);
    }
    return got;
  };
  char head[1 + sizeof(std::uint64_t)];
  const std::size_t head_size = read_some(head, 1);
  std::uint64_t scene_size = 0;
  if (head_size == 1 && head[0] == 'S' && read_some(head + 1, sizeof scene_size) == sizeof scene_size) {
    std::memcpy(&scene_size, head + 1, sizeof scene_size);
    try {
      message.resize(1 + static_cast<std::size_t>(scene_size));
      message[0] = 'S';
      message.resize(1 + read_some(message.data() + 1, static_cast<std::size_t>(scene_size)));
    } catch (const std::exception&) {  // bad_alloc, or length_error for a size past max_size
      out_of_memory = true;
      message.clear();
      kill(pid, SIGKILL);  // it would block on the pipe otherwise
    }
  } else if (head_size == 1) {
    message.assign(head, 1);
    char buf[4096];
    for (std::size_t n; (n = read_some(buf, sizeof buf)) > 0;) message.append(buf, n);
  }
  close(fds[0]);
  int wait_status = 0;
  while (waitpid(pid, &wait_status, 0) < 0 && errno == EINTR) {
  }
  const CrashNote note = *static_cast<const CrashNote*>(shared);
  munmap(shared, sizeof(CrashNote));

  if (out_of_memory) return Status::OutOfMemory("out of memory receiving the parsed scene");
  if (timed_out) {
    char secs[32];
    std::snprintf(secs, sizeof secs, "%.0f", limit_s);
    return Status::ParseError(std::string("assimp, the model reader, was still parsing this file after ") + secs +
                              " s and was stopped: the file is probably malformed (a loop in the parser). For a "
                              "large file that needs longer, set G2P_READ_TIMEOUT=SECONDS");
  }
  const bool clean_exit = WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0;
  if (!clean_exit || message.empty()) return child_failure(wait_status, note);
  switch (message[0]) {
    case 'E': return Status::ParseError(message.substr(1));
    case 'M': return Status::OutOfMemory("out of memory while parsing the file");
    case 'S': {
      Result<OwnedScene> scene = decode_scene(std::string_view(message).substr(1));
      if (!scene.ok()) return scene.status();
      parsed.owned_ = std::move(*scene);
      return parsed;
    }
    default: return Status::Internal("the model reader sent an unknown reply");
  }
}

}  // namespace g2p::detail
