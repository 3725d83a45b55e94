// g2p complete SOURCE -o OUT: stage 5, every part closed into a watertight
// volume. SOURCE is a `g2p project`/`g2p refine` folder or a model file with
// its ground truth (--truth labels.json).
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "g2p/complete.h"
#if defined(G2P_CLI_WITH_CGAL)
#include "g2p/complete_cgal.h"
#endif
#include "g2p/io.h"
#include "stage_inputs.h"

namespace g2p::cli {
namespace {

struct CompleteArgs {
  LabelledSourceArgs source;
  std::string out;
  std::string completer = "partition";
  std::vector<std::string> settings;
  std::string fallback = "partition";
  std::vector<std::string> formats{"obj"};
};

Result<BackendSettings> parse_settings(const std::vector<std::string>& pairs) {
  BackendSettings s;
  for (const std::string& p : pairs) {
    const std::size_t eq = p.find('=');
    if (eq == std::string::npos || eq == 0) return Status::InvalidArgument("expected KEY=VALUE, got '" + p + "'");
    s[p.substr(0, eq)] = p.substr(eq + 1);
  }
  return s;
}

int run_complete(const CompleteArgs& args) {
  int exit_code = kExitOk;
  Result<LabelledObject> object = load_labelled_source("complete", args.source, exit_code);
  if (!object.ok()) return exit_code;
  Result<BackendSettings> settings = parse_settings(args.settings);
  if (!settings.ok()) {
    std::cerr << "g2p complete: error: --complete-set: " << settings.status().message() << "\n";
    return kExitUsage;
  }
#if defined(G2P_CLI_WITH_CGAL)
  if (Status s = register_cgal_completers(); !s.ok()) {
    std::cerr << "g2p complete: error: " << s.to_string() << "\n";
    return kExitFailure;
  }
#endif
  Result<std::unique_ptr<Completer>> completer = make_completer(args.completer, *settings);
  if (!completer.ok()) {
    std::cerr << "g2p complete: error: " << completer.status().to_string() << "\n";
    return kExitUsage;
  }
  std::unique_ptr<Completer> fallback;
  if (args.fallback != "none" && args.fallback != args.completer) {
    Result<std::unique_ptr<Completer>> f = make_completer(args.fallback);
    if (!f.ok()) {
      std::cerr << "g2p complete: error: --fallback: " << f.status().to_string() << "\n";
      return kExitUsage;
    }
    fallback = std::move(*f);
  }
  const auto start = std::chrono::steady_clock::now();
  CompletionInput input{&object->model.mesh, &object->faces.parts, &object->table};
  Result<Completion> done = complete(input, **completer, fallback.get());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!done.ok()) {
    std::cerr << "g2p complete: error: " << done.status().to_string() << "\n";
    return kExitFailure;
  }
  const std::string out = args.out.empty() ? args.source.source + "/completed" : args.out;
  Status s = write_completion(out, *done, object->table, args.formats);
  if (!s.ok()) {
    std::cerr << "g2p complete: error: " << s.to_string() << "\n";
    return kExitFailure;
  }
  int failed = 0;
  for (const CompletedPart& p : done->parts) failed += !p.ok;
  std::cout << "completed " << done->parts.size() << " parts of " << object->origin << " with '" << args.completer
            << "' in " << std::fixed << std::setprecision(2) << seconds << " s -> " << out << "\n";
  for (const std::string& n : done->notes) std::cout << "  " << n << "\n";
  for (const CompletedPart& p : done->parts) {
    const std::string name = object->table.valid_label(p.label) ? object->table[p.label].name : "Unknown";
    std::cout << "  part " << p.part << " " << name << ": " << (p.ok ? "ok" : "FAILED") << ", " << std::setprecision(6)
              << p.checks.volume_m3 * 1e6 << " cm^3, " << p.mesh.num_faces() << " triangles (" << p.backend << ")";
    for (const std::string& n : p.notes) std::cout << "; " << n;
    std::cout << "\n";
  }
  std::cout << "  object " << done->object_volume_m3 * 1e6 << " cm^3, parts sum " << done->parts_volume_m3 * 1e6
            << " cm^3\n";
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
  cmd->add_option("--completer", args->completer,
                  "Backend: partition (default), external, alpha-wrap and fill (CGAL builds)");
  cmd->add_option("--complete-set", args->settings, "Backend setting KEY=VALUE (repeatable), e.g. resolution=200");
  cmd->add_option("--fallback", args->fallback, "Backend for parts the completer fails, or 'none' (default partition)");
  cmd->add_option("--format", args->formats, "Mesh formats to write: obj, ply, stl (comma-separated)")
      ->delimiter(',')
      ->check(CLI::IsMember({"obj", "ply", "stl"}));
  cmd->callback([args, &run] { run = [args] { return run_complete(*args); }; });
}

}  // namespace g2p::cli
