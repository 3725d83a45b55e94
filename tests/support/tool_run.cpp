#include "support/tool_run.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>

#include "support/test_data.h"

namespace g2p::test {

ToolRun run_tool(const std::string& args) {
  static int counter = 0;  // ctest runs tests in parallel processes: one folder per run
  const std::string dir = scratch_dir("tool_run_" + std::to_string(::getpid()) + "_" + std::to_string(++counter));
  const std::string cmd = quote(G2P_TEST_TOOL) + " " + args + " >" + quote(dir + "/out") + " 2>" + quote(dir + "/err");
  const int status = std::system(cmd.c_str());
  ToolRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(dir + "/out");
  r.err = read_file(dir + "/err");
  return r;
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace g2p::test
