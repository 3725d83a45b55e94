// g2p identify MODEL: what the object is (the pipeline run up to its identify
// step), and g2p identify --list: the kinds of the object table.
#include <cstdio>
#include <iostream>

#include "commands.h"
#include "common.h"
#include "g2p/pipeline.h"
#include "stage_flags.h"

namespace g2p::cli {
namespace {

struct IdentifyCommandArgs {
  std::string model;
  PipelineArgs pipeline;  // its import, view and identify flags and --anonymize-names
  bool list = false;
  bool json = false;
};

int usage(const std::string& message) {
  std::cerr << "g2p identify: " << message << "\n";
  return kExitUsage;
}

int list_kinds(bool as_json) {
  const ObjectTable& table = ObjectTable::shipped();
  if (as_json) {
    std::cout << object_kinds_json(table) << "\n";
    return kExitOk;
  }
  std::printf("%-24s %-12s %10s %18s  %s\n", "kind", "group", "longest m", "mass kg", "structure");
  for (const ObjectKind& k : table.kinds())
    std::printf("%-24s %-12s %10.3g %8.3g-%-9.3g  %s\n", k.name.c_str(), k.group.c_str(), k.typical_longest_side_m,
                k.mass_kg[0], k.mass_kg[1], k.structure.c_str());
  std::printf("%d kinds (libg2p/data/objects.json; its card objects.md says where every figure comes from)\n",
              table.size());
  return kExitOk;
}

int run_identify(const IdentifyCommandArgs& args) {
  if (args.list) return list_kinds(args.json);
  if (args.model.empty()) return usage("give a MODEL file, or --list");
  Result<PipelineOptions> o = pipeline_options(args.pipeline);
  if (!o.ok()) return usage(o.status().message());
  o->last_stage = Stage::kIdentify;
  Pipeline pipeline(std::move(*o));
  Result<PipelineResult> r = pipeline.run_file(args.model);
  if (!r.ok()) return fail_or_usage("identify", r.status());
  const Identification& id = r->identification;
  if (args.json) {
    std::cout << identification_json(id, ObjectTable::shipped(), r->size_assumed_m) << "\n";
    return kExitOk;
  }
  for (const std::string& w : r->warnings) std::cerr << "g2p identify: warning: " << w << "\n";
  if (!id.known()) {
    std::printf("%s: unknown (no source could tell; give it with --object)\n", args.model.c_str());
  } else {
    const KindGuess& best = id.candidates.front();
    std::printf("%s: %s (%s, %.0f %% confident: %s)\n", args.model.c_str(), best.kind.c_str(), best.source.c_str(),
                100.0 * best.confidence, best.evidence.c_str());
  }
  for (std::size_t i = id.known() ? 1 : 0; i < id.candidates.size() && i < 5; ++i)
    std::printf("  or %s (%s, %.0f %%: %s)\n", id.candidates[i].kind.c_str(), id.candidates[i].source.c_str(),
                100.0 * id.candidates[i].confidence, id.candidates[i].evidence.c_str());
  for (const std::string& n : id.notes) std::printf("  note: %s\n", n.c_str());
  if (!r->kind.name.empty())
    std::printf("  a %s is usually %.3g-%.3g m long and weighs %.3g-%.3g kg\n", r->kind.name.c_str(),
                r->kind.longest_side_m[0], r->kind.longest_side_m[1], r->kind.mass_kg[0], r->kind.mass_kg[1]);
  if (r->size_assumed_m > 0)
    std::printf(
        "  g2p run would give it a longest side of %.3g m (the file looks normalised; --size-from file keeps "
        "it)\n",
        r->size_assumed_m);
  return kExitOk;
}

}  // namespace

void add_identify_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<IdentifyCommandArgs>();
  CLI::App* cmd = app.add_subcommand(
      "identify", "What the object is: its kind, from your words, the file's names and the rendered views");
  cmd->add_option("model", args->model, "Model file (glTF/GLB, OBJ, PLY, STL, FBX, ...)");
  cmd->add_flag("--list", args->list, "List the kinds of the object table instead");
  cmd->add_flag("--json", args->json, "Print JSON (report.json's \"identification\") instead of text");
  cmd->add_flag("--anonymize-names", args->pipeline.anonymize, "Replace every name by a meaningless one first");
  add_import_flags(cmd, args->pipeline.import);
  add_view_flags(cmd, args->pipeline.views);
  add_identify_flags(cmd, args->pipeline.identify);
  cmd->callback([args, &run] { run = [args] { return run_identify(*args); }; });
}

}  // namespace g2p::cli
