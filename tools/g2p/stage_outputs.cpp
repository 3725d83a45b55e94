#include "stage_outputs.h"

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

int refine_projection(const std::string& command, const RefineArgs& args, const Model& model,
                      const std::vector<View>& views, const MaterialTable& table,
                      const PartitionOptions& partition_options, Projection& projection, nlohmann::json& report) {
  report = {{"refiner", args.name}};
  if (args.name == "none") {
    if (!args.settings.empty()) {
      std::cerr << "g2p " << command << ": --refine-set needs a --refiner other than none\n";
      return kExitUsage;
    }
    return kExitOk;
  }
  BackendSettings settings;
  for (const std::string& kv : args.settings) {
    const std::size_t eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) {
      std::cerr << "g2p " << command << ": --refine-set expects KEY=VALUE, got '" << kv << "'\n";
      return kExitUsage;
    }
    settings[kv.substr(0, eq)] = kv.substr(eq + 1);
  }
  Result<std::unique_ptr<Refiner>> refiner = make_refiner(args.name, settings);
  if (!refiner.ok()) {
    std::cerr << "g2p " << command << ": " << refiner.status().message() << "\n";
    return kExitUsage;
  }
  RefineInput in{&model.mesh, &projection.graph, &projection.votes, &projection.labels, &views, &table};
  Result<RefineResult> refined = (*refiner)->refine(in);
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
  const std::vector<float> voted_confidence = projection.labels.confidence;
  projection.labels.label = refined->labels;
  projection.parts = partition(model.mesh, projection.graph, projection.labels.label, projection.face_part,
                               partition_options, &voted_confidence);
  for (int f = 0; f < model.mesh.num_faces(); ++f) {
    const float* h = projection.votes.of(f);
    const int l = projection.labels.label[static_cast<std::size_t>(f)];
    const float t = projection.votes.total[static_cast<std::size_t>(f)];
    projection.labels.confidence[static_cast<std::size_t>(f)] = h != nullptr && t > 0.f && l >= 0 ? h[l] / t : 0.f;
  }
  report["notes"] = refined->notes;
  report["changed_faces"] = refined->changes.size();
  nlohmann::json changes = nlohmann::json::array();
  for (std::size_t i = 0; i < refined->changes.size() && i < 1000; ++i) {
    const LabelChange& c = refined->changes[i];
    changes.push_back({{"face", c.face}, {"from", c.from}, {"to", c.to}, {"reason", c.reason}});
  }
  report["changes_first_1000"] = changes;
  for (const std::string& n : refined->notes) std::cout << n << "\n";
  return kExitOk;
}

Status write_projection(const std::string& out, const Model& model, const std::vector<View>& views,
                        const Projection& projection, const MaterialTable& table, const nlohmann::json& report) {
  // The labels seen through every view: what the refine stage (and a person) looks at.
  std::vector<LabelMap> projected;
  for (const View& v : views) projected.push_back(render_face_labels(v, projection.labels.label));
  Status s = write_label_maps(out + "/projected", projected, table);
  if (s.ok()) s = write_faces_csv(out + "/faces.csv", model, projection, table);
  if (s.ok()) s = write_labelled_ply(out + "/labelled.ply", model.mesh, projection.labels.label, table);
  nlohmann::json parts = nlohmann::json::array();
  for (std::size_t i = 0; i < projection.parts.size(); ++i) {
    const Part& p = projection.parts[i];
    parts.push_back({{"part", i},
                     {"label", table.valid_label(p.label) ? table[p.label].name : std::string()},
                     {"faces", p.faces.size()},
                     {"area_m2", p.area_m2}});
  }
  if (s.ok()) s = write_text_file(out + "/refine.json", report.dump(2) + "\n");
  if (s.ok()) s = write_text_file(out + "/parts.json", nlohmann::json{{"parts", parts}}.dump(2) + "\n");
  return s;
}

void print_parts(const Projection& projection, const MaterialTable& table) {
  for (std::size_t i = 0; i < projection.parts.size(); ++i) {
    const Part& p = projection.parts[i];
    std::printf("  part %zu: %s, %zu faces, %.6g m^2\n", i,
                table.valid_label(p.label) ? table[p.label].name.c_str() : "(unknown)", p.faces.size(), p.area_m2);
  }
}

}  // namespace g2p::cli
