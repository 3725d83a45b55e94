#include "support/tool_run.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "support/test_data.h"

namespace g2p::test {

ToolRun run_tool(const std::string& args) { return run_command(quote(G2P_TEST_TOOL) + " " + args); }

int spawn_tool(const std::vector<std::string>& args, const std::string& stderr_path) {
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDERR_FILENO, stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  std::vector<std::string> words{G2P_TEST_TOOL};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, G2P_TEST_TOOL, &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  return rc == 0 ? pid : -1;
}

ToolRun run_command(const std::string& command_line) {
  static int counter = 0;  // ctest runs tests in parallel processes: one folder per run
  const std::string dir = scratch_dir("tool_run_" + std::to_string(::getpid()) + "_" + std::to_string(++counter));
  const std::string cmd = command_line + " >" + quote(dir + "/out") + " 2>" + quote(dir + "/err");
  const int status = std::system(cmd.c_str());
  ToolRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(dir + "/out");
  r.err = read_file(dir + "/err");
  return r;
}

ValidatorRun run_gltf_validator(const std::string& path) {
  const std::string script = source_path("tests/validators/gltf_validate.js");
  ValidatorRun v;
  v.available = std::filesystem::exists(source_path("tests/validators/node_modules/gltf-validator/package.json")) &&
                std::system("command -v node >/dev/null 2>&1") == 0;
  if (v.available) v.run = run_command("node " + quote(script) + " " + quote(path));
  return v;
}

ValidatorRun run_summary_browser(const std::string& page, const std::string& args) {
  ValidatorRun v;
  const char* chromium = std::getenv("G2P_CHROMIUM");
  const std::string browser = chromium != nullptr && *chromium != '\0' ? chromium : "/usr/bin/chromium";
  if (std::system("command -v node >/dev/null 2>&1") != 0)
    v.missing = "node";
  else if (!std::filesystem::exists(source_path("tests/validators/node_modules/playwright-core/package.json")))
    v.missing = "the npm playwright-core in tests/validators";
  else if (!std::filesystem::exists(browser))
    v.missing = "Chromium (" + browser + "; set G2P_CHROMIUM to another)";
  v.available = v.missing.empty();
  if (v.available)
    v.run = run_command("node " + quote(source_path("tests/validators/summary_browser.js")) + " " + quote(page) +
                        (args.empty() ? "" : " " + args));
  return v;
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace g2p::test
