// The g2p tool's subcommands. Each registers itself on the app and runs the
// library; main() only dispatches.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace g2p::cli {

// Documented exit codes of every subcommand.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,       // the library reported an error (bad input file, ...)
  kExitUsage = 2,         // bad command line
  kExitCancelled = 130,   // interrupted (Ctrl-C); nothing was written
  kExitTerminated = 143,  // terminated (SIGTERM); nothing was written
};

// Adds a subcommand; the returned function runs it after parsing.
using Command = std::function<int()>;
void add_info_command(CLI::App& app, Command& run);
void add_render_command(CLI::App& app, Command& run);
void add_segment_command(CLI::App& app, Command& run);
void add_eval_command(CLI::App& app, Command& run);
void add_project_command(CLI::App& app, Command& run);
void add_refine_command(CLI::App& app, Command& run);
void add_complete_command(CLI::App& app, Command& run);
void add_properties_command(CLI::App& app, Command& run);
void add_export_command(CLI::App& app, Command& run);  // export, and validate with it
void add_validate_command(CLI::App& app, Command& run);
void add_run_command(CLI::App& app, Command& run);       // the whole pipeline
void add_batch_command(CLI::App& app, Command& run);     // many models, one process each
void add_identify_command(CLI::App& app, Command& run);  // what the object is

}  // namespace g2p::cli
