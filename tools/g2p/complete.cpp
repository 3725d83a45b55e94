// g2p complete SOURCE -o OUT: stage 5, every part closed into a watertight
// volume. SOURCE is a `g2p project`/`g2p refine` folder or a model file with
// its ground truth (--truth labels.json).
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "commands.h"
#include "g2p/complete.h"
#include "stage_inputs.h"

namespace g2p::cli {
namespace {

struct CompleteArgs {
  LabelledSourceArgs source;
  CompleterArgs completer;
  std::string out;
  std::vector<std::string> formats{"obj"};
};

int run_complete(const CompleteArgs& args) {
  int exit_code = kExitOk;
  if (args.out.empty() && !std::filesystem::is_directory(args.source.source)) {
    std::cerr << "g2p complete: error: give -o OUT for a model file\n";
    return kExitUsage;
  }
  Result<LabelledObject> object = load_labelled_source("complete", args.source, exit_code);
  if (!object.ok()) return exit_code;
  Result<Completion> done = run_completion("complete", args.completer, *object, exit_code);
  if (!done.ok()) return exit_code;
  const std::string out = args.out.empty() ? args.source.source + "/completed" : args.out;
  Status s = write_completion(out, *done, object->table, args.formats);
  // The corrections the closed parts were made with, for the record (the
  // closed meshes alone do not carry classes on to later commands).
  if (s.ok()) s = write_overrides(out, object->overrides, object->table);
  if (!s.ok()) {
    std::cerr << "g2p complete: error: " << s.to_string() << "\n";
    return kExitFailure;
  }
  std::cout << "  -> " << out << "\n";
  int failed = 0;
  for (const CompletedPart& p : done->parts) failed += !p.ok;
  if (failed > 0) {
    std::cerr << "g2p complete: " << failed << " part(s) failed their checks (see completion.json)\n";
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace

void add_complete_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<CompleteArgs>();
  CLI::App* cmd = app.add_subcommand("complete", "Close every part into a watertight volume (stage 5)");
  add_labelled_source_flags(cmd, args->source);
  cmd->add_option("-o,--output", args->out, "Output folder (default SOURCE/completed)");
  add_completer_flags(cmd, args->completer);
  cmd->add_option("--format", args->formats, "Mesh formats to write: obj, ply, stl (comma-separated)")
      ->delimiter(',')
      ->check(CLI::IsMember({"obj", "ply", "stl"}));
  cmd->callback([args, &run] { run = [args] { return run_complete(*args); }; });
}

}  // namespace g2p::cli
