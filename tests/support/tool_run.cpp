#include "support/tool_run.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "support/test_data.h"

namespace g2p::test {

ToolRun run_tool(const std::string& args) { return run_command(quote(G2P_TEST_TOOL) + " " + args); }

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
