// g2p: command-line front end of libg2p. Thin: parses flags into the library's
// option structs, calls the library, reports and exits non-zero on failure.
#include <iostream>

#include "commands.h"
#include "g2p/version.h"

int main(int argc, char** argv) {
  CLI::App app{"g2p: ground static 3D meshes in physics (Gen2Physics)"};
  app.set_version_flag("--version", std::string("g2p ") + g2p::version());
  app.require_subcommand(1);

  g2p::cli::Command run;
  g2p::cli::add_run_command(app, run);
  g2p::cli::add_batch_command(app, run);
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
  return run ? run() : g2p::cli::kExitUsage;
}
