// Flags and helpers shared by the g2p subcommands.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "g2p/io.h"

namespace g2p::cli {

// How a model file is read: --unit, --up, --keep-axes, --no-textures.
struct ImportArgs {
  std::string unit;  // "" = from the format
  std::string up = "auto";
  bool keep_axes = false;
  bool no_textures = false;
};

void add_import_flags(CLI::App* cmd, ImportArgs& args);

// Loads `path` with the flags; on failure prints "g2p COMMAND: error: ..." and
// returns the exit code in `exit_code`.
Result<Model> load_with_flags(const std::string& command, const std::string& path, const ImportArgs& args,
                              int& exit_code);

}  // namespace g2p::cli
