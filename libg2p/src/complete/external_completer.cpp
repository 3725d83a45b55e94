// The `external` completer: a user command (a HoloPart wrapper, a remeshing
// tool) closes each part. libg2p writes the part's patch and the whole object
// to a private temporary folder, runs the command through /bin/sh with the
// placeholders replaced, reads the closed mesh back and checks it like any
// other backend's. A command that fails, times out or returns a mesh that is
// not watertight leaves the part not ok, so complete() falls back.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "complete/backends.h"
#include "core/settings.h"
#include "g2p/io.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

void replace_all(std::string& s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
}

// Runs `command` with /bin/sh in its own process group; kills the group
// after `timeout_s`. Returns the exit status or an error.
Status run_command(const std::string& command, double timeout_s) {
  const pid_t pid = fork();
  if (pid < 0) return Status::Internal("external: fork failed");
  if (pid == 0) {
    setpgid(0, 0);
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  setpgid(pid, pid);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  for (;;) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0) return Status::Internal("external: waitpid failed");
    if (std::chrono::steady_clock::now() > deadline) {
      kill(-pid, SIGKILL);
      waitpid(pid, &status, 0);
      return Status::Unavailable("external: the command ran longer than " + std::to_string(timeout_s) +
                                 " s and was killed");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return Status::Ok();
  if (WIFEXITED(status))
    return Status::Unavailable("external: the command exited with status " + std::to_string(WEXITSTATUS(status)));
  return Status::Unavailable("external: the command was killed by signal " + std::to_string(WTERMSIG(status)));
}

class ExternalCompleter final : public Completer {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("external")
        .text("command", command_,
              "the command closing one part: {input}, {output}, {object}, {label} and {part} are replaced")
        .number("timeout", timeout_s_, Range::above(0), "s", "per part")
        .choice("format", format_, {{"obj", "obj"}, {"ply", "ply"}, {"stl", "stl"}}, "the mesh format exchanged")
        .number("max_relative_distance", max_relative_distance_, Range::above(0), "",
                "a part whose surface strays farther from its patch (x the patch's diagonal) fails")
        .check([this] {
          if (command_.empty() || command_.find("{output}") != std::string::npos) return Status::Ok();
          return Status::InvalidArgument(
              "external: the command must contain {output} (where it writes the closed mesh)");
        });
  }

  Result<Completion> complete(const CompletionInput& input) const override {
    if (command_.empty())
      return Status::InvalidArgument(
          "external: no command (set command=\"tool {input} {output}\"; placeholders {input}, {output}, {object}, "
          "{label}, {part})");
    if (input.mesh == nullptr || input.parts == nullptr)
      return Status::InvalidArgument("external: needs the mesh and the parts");
    std::string tmpl = (fs::temp_directory_path() / "g2p-complete-XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) return Status::IoError("external: cannot create a temporary folder");
    const fs::path work(tmpl);
    const std::string object_path = (work / ("object." + format_)).string();
    G2P_RETURN_IF_ERROR(write_mesh(object_path, *input.mesh));

    Result<Completion> result = complete_each_part(
        input, "external", max_relative_distance_, [&](int p, const Mesh& patch, CompletedPart& out) -> Status {
          const Part& part = (*input.parts)[static_cast<std::size_t>(p)];
          const std::string stem = (work / ("part_" + std::to_string(p))).string();
          const std::string in_path = stem + "." + format_, out_path = stem + "_closed." + format_;
          const std::string label = input.table != nullptr && input.table->valid_label(part.label)
                                        ? (*input.table)[part.label].name
                                        : "Unknown";
          G2P_RETURN_IF_ERROR(write_mesh(in_path, patch));
          std::string cmd = command_;
          replace_all(cmd, "{input}", shell_quote(in_path));
          replace_all(cmd, "{output}", shell_quote(out_path));
          replace_all(cmd, "{object}", shell_quote(object_path));
          replace_all(cmd, "{label}", shell_quote(label));
          replace_all(cmd, "{part}", std::to_string(p));
          G2P_RETURN_IF_ERROR(run_command(cmd, timeout_s_));
          ImportOptions io;
          io.z_up = false;  // the command answers in the frame it was given
          io.unit_scale = 1.0;
          io.up_axis = UpAxis::kZ;
          io.load_textures = false;
          Result<Model> closed = load_model(out_path, io);
          if (!closed.ok()) return closed.status();
          out.mesh.positions = std::move(closed->mesh.positions);
          out.mesh.triangles = std::move(closed->mesh.triangles);
          return Status::Ok();
        });
    std::error_code ec;
    fs::remove_all(work, ec);
    return result;
  }

 private:
  std::string command_;
  double timeout_s_ = 600.0;
  std::string format_ = "obj";
  double max_relative_distance_ = 0.25;
};

}  // namespace

std::unique_ptr<Completer> make_external_completer() { return std::make_unique<ExternalCompleter>(); }

}  // namespace g2p
