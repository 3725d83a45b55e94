#include "stage_outputs.h"
#include "json_out.h"

#include <iostream>

#include "commands.h"
#include "g2p/io.h"

namespace g2p::cli {

void add_refiner_flags(CLI::App* cmd, RefineArgs& args, const std::string& default_name) {
  args.name = default_name;
  cmd->add_option(
      "--refiner", args.name,
      "Refiner: none, smooth, vlm (vlm needs --refine-set model=NAME --refine-set url=URL); default " + default_name);
  cmd->add_option("--refine-set", args.settings,
                  "Refiner setting KEY=VALUE, repeatable (smooth: lambda, island, sweeps; vlm: url, model, "
                  "api_key_env, timeout, retries, backoff, max_response_bytes, prompt_file, max_views)");
}

Result<std::unique_ptr<Refiner>> make_refiner_flag(const std::string& command, const RefineArgs& args, int& exit_code) {
  exit_code = kExitUsage;
  if (args.name == "none") {
    if (!args.settings.empty()) {
      std::cerr << "g2p " << command << ": --refine-set needs a --refiner other than none\n";
      return Status::InvalidArgument("--refine-set without --refiner");
    }
    exit_code = kExitOk;
    return std::unique_ptr<Refiner>();  // no refiner
  }
  BackendSettings settings;
  for (const std::string& kv : args.settings) {
    const std::size_t eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) {
      std::cerr << "g2p " << command << ": --refine-set expects KEY=VALUE, got '" << kv << "'\n";
      return Status::InvalidArgument("bad --refine-set");
    }
    settings[kv.substr(0, eq)] = kv.substr(eq + 1);
  }
  Result<std::unique_ptr<Refiner>> refiner = make_refiner(args.name, settings);
  if (!refiner.ok()) {
    std::cerr << "g2p " << command << ": " << refiner.status().message() << "\n";
    return refiner.status();
  }
  exit_code = kExitOk;
  return refiner;
}

int apply_refiner(const std::string& command, const std::string& name, const Refiner* refiner, const Model& model,
                  const std::vector<View>& views, const MaterialTable& table, const PartitionOptions& partition_options,
                  Projection& projection, nlohmann::json& report, bool print_notes,
                  const std::vector<std::uint8_t>* image_decided, const std::vector<float>* class_prior) {
  report = {{"refiner", name}};
  if (refiner == nullptr) return kExitOk;
  RefineInput in{&model.mesh, &projection.graph, &projection.votes, &projection.labels, &views,
                 &table,      image_decided,     class_prior};
  Result<RefineResult> refined = refiner->refine(in);
  if (!refined.ok() &&
      (refined.status().code() == StatusCode::kInvalidArgument || refined.status().code() == StatusCode::kNotFound)) {
    // Missing settings (no model name, an unreadable prompt file): the command line is wrong.
    std::cerr << "g2p " << command << ": " << refined.status().message() << "\n";
    return kExitUsage;
  }
  if (!refined.ok()) {
    // An optional stage: its failure loses nothing, the projected labels stand.
    std::cerr << "g2p " << command
              << ": warning: refine failed, keeping the projected labels: " << refined.status().to_string() << "\n";
    report["error"] = refined.status().to_string();
    return kExitOk;
  }
  if (Status s = apply_refinement(model.mesh, refined->labels, partition_options, projection); !s.ok()) {
    std::cerr << "g2p " << command << ": error: " << s.to_string() << "\n";
    return kExitFailure;
  }
  report["notes"] = refined->notes;
  report["changed_faces"] = refined->changes.size();
  nlohmann::json changes = nlohmann::json::array();
  for (std::size_t i = 0; i < refined->changes.size() && i < 1000; ++i) {
    const LabelChange& c = refined->changes[i];
    changes.push_back({{"face", c.face}, {"from", c.from}, {"to", c.to}, {"reason", c.reason}});
  }
  report["changes_first_1000"] = changes;
  if (print_notes)
    for (const std::string& n : refined->notes) std::cout << n << "\n";
  return kExitOk;
}

int refine_projection(const std::string& command, const RefineArgs& args, const Model& model,
                      const std::vector<View>& views, const MaterialTable& table,
                      const PartitionOptions& partition_options, Projection& projection, nlohmann::json& report,
                      const std::vector<std::uint8_t>* image_decided) {
  int exit_code = kExitOk;
  Result<std::unique_ptr<Refiner>> refiner = make_refiner_flag(command, args, exit_code);
  if (!refiner.ok()) return exit_code;
  return apply_refiner(command, args.name, refiner->get(), model, views, table, partition_options, projection, report,
                       /*print_notes=*/true, image_decided);
}

Status write_projection(const std::string& out, const Model& model, const std::vector<View>& views,
                        const Projection& projection, const MaterialTable& table, const nlohmann::json& report) {
  G2P_RETURN_IF_ERROR(g2p::write_projection(out, model, views, projection, table));
  return write_text_file(out + "/refine.json", json_out(report) + "\n");
}

void print_parts(const Projection& projection, const MaterialTable& table) {
  for (std::size_t i = 0; i < projection.parts.size(); ++i) {
    const Part& p = projection.parts[i];
    std::printf("  part %zu: %s, %zu faces, %.6g m^2\n", i,
                table.valid_label(p.label) ? table[p.label].name.c_str() : "(unknown)", p.faces.size(), p.area_m2);
  }
}

}  // namespace g2p::cli
