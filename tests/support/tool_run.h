// Runs the g2p command-line tool as a user would, capturing its output.
#pragma once

#include <string>

namespace g2p::test {

struct ToolRun {
  int exit_code = -1;
  std::string out, err;
};

// Runs `g2p ARGS` (ARGS already shell-quoted where needed).
ToolRun run_tool(const std::string& args);

// Single-quotes a string for the shell.
std::string quote(const std::string& s);

}  // namespace g2p::test
