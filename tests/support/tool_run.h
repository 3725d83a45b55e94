// Runs the g2p command-line tool as a user would, capturing its output.
#pragma once

#include <string>
#include <vector>

namespace g2p::test {

struct ToolRun {
  int exit_code = -1;
  std::string out, err;
};

// Runs `g2p ARGS` (ARGS already shell-quoted where needed).
ToolRun run_tool(const std::string& args);

// Starts `g2p ARGS` in the background (argv words, no shell), stdout on
// /dev/null and stderr into `stderr_path`; returns its pid (-1 on failure).
int spawn_tool(const std::vector<std::string>& args, const std::string& stderr_path);

// Runs a shell command line as given, capturing its output.
ToolRun run_command(const std::string& command_line);

// The Khronos glTF validator (npm gltf-validator, which scripts/install-deps.sh
// installs into tests/validators) on one file; exit 0 = no errors. Not
// `available` when node or the package is missing (the caller skips, saying so).
struct ValidatorRun {
  bool available = false;
  std::string missing;  // what is not installed, when not available
  ToolRun run;
};
ValidatorRun run_gltf_validator(const std::string& path);

// tests/validators/summary_browser.js: a summary.html in headless Chromium
// (playwright-core from tests/validators, the browser at $G2P_CHROMIUM or
// /usr/bin/chromium). `args` go after the page, already shell-quoted.
ValidatorRun run_summary_browser(const std::string& page, const std::string& args = "");

// Single-quotes a string for the shell.
std::string quote(const std::string& s);

}  // namespace g2p::test
