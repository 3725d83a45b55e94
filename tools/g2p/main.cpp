// g2p: command-line front end of libg2p. Thin: parses flags into the library's
// option structs, calls the library, reports and exits non-zero on failure.
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include "commands.h"
#include "g2p/version.h"

int main(int argc, char** argv) {
  CLI::App app{"g2p: ground static 3D meshes in physics (Gen2Physics)"};
  app.set_version_flag("--version", std::string("g2p ") + g2p::version());
  app.require_subcommand(1);

  g2p::cli::Command run;
  g2p::cli::add_run_command(app, run);
  g2p::cli::add_batch_command(app, run);
  g2p::cli::add_identify_command(app, run);
  g2p::cli::add_info_command(app, run);
  g2p::cli::add_render_command(app, run);
  g2p::cli::add_segment_command(app, run);
  g2p::cli::add_project_command(app, run);
  g2p::cli::add_refine_command(app, run);
  g2p::cli::add_complete_command(app, run);
  g2p::cli::add_properties_command(app, run);
  g2p::cli::add_export_command(app, run);
  g2p::cli::add_eval_command(app, run);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? g2p::cli::kExitOk : g2p::cli::kExitUsage;
  }
  if (!run) return g2p::cli::kExitUsage;
  // The commands report failures as Status; an exception reaching here is out
  // of memory or a bug. Catching it unwinds the stack, so a command's
  // temporary folders are removed, and the user gets a line, not an abort.
  const std::string command =
      app.get_subcommands().empty() ? std::string("g2p") : "g2p " + app.get_subcommands().front()->get_name();
  try {
    return run();
  } catch (const std::bad_alloc&) {
    std::cerr << command << ": error: out of memory (fewer or smaller views, --views and --resolution, need less)\n";
  } catch (const std::exception& e) {
    std::cerr << command << ": internal error: " << e.what() << " (a bug in g2p; please report it with the command)\n";
  }
  return g2p::cli::kExitFailure;
}
