#include "stage_inputs.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "g2p/segment.h"
#if defined(G2P_CLI_WITH_CGAL)
#include "g2p/complete_cgal.h"
#endif

namespace g2p::cli {
namespace {

Result<std::string> read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

void add_labelled_source_flags(CLI::App* cmd, LabelledSourceArgs& args) {
  cmd->add_option("source", args.source,
                  "Output folder of g2p project or g2p refine, or a model file together with --truth")
      ->required();
  cmd->add_option("--truth", args.truth, "For a model file: labels.json with its ground-truth material classes");
  cmd->add_option("--key", args.key, "Entry of --truth to use (default: the model file's stem)");
  cmd->add_option("--materials", args.materials,
                  "Material table JSON (default: the folder's, else the paper's 12 classes)");
}

Result<LabelledObject> load_labelled_source(const std::string& command, const LabelledSourceArgs& args,
                                            int& exit_code) {
  auto fail = [&](const Status& s, int code) -> Status {
    std::cerr << "g2p " << command << ": error: " << s.to_string() << "\n";
    exit_code = code;
    return s;
  };
  LabelledObject out;
  namespace fs = std::filesystem;
  if (fs::is_directory(args.source)) {
    if (!args.truth.empty())
      return fail(Status::InvalidArgument("--truth is for model files; " + args.source + " is a folder"), kExitUsage);
    Result<std::string> text = read_text(args.source + "/project.json");
    if (!text.ok())
      return fail(Status::NotFound(args.source + "/project.json: missing (is this a g2p project or refine folder?)"),
                  kExitFailure);
    const nlohmann::json manifest = nlohmann::json::parse(*text, nullptr, false);
    if (manifest.is_discarded() || manifest.value("format", "") != "g2p-project")
      return fail(Status::ParseError(args.source + "/project.json: not a g2p-project manifest"), kExitFailure);
    ImportArgs import;
    const nlohmann::json imp = manifest.value("import", nlohmann::json::object());
    import.unit = imp.value("unit", "");
    import.up = imp.value("up", "auto");
    import.keep_axes = imp.value("keep_axes", false);
    import.no_textures = !args.textures;  // most later stages need geometry only
    Result<Model> model = load_with_flags(command, manifest.value("model", ""), import, exit_code);
    if (!model.ok()) return model.status();
    out.model = std::move(*model);
    const std::string table_path = args.materials.empty() ? manifest.value("materials", "") : args.materials;
    Result<MaterialTable> table = load_table_flag(command, table_path, exit_code);
    if (!table.ok()) return table.status();
    out.table = std::move(*table);
    Result<FacesFile> faces = read_faces_csv(args.source + "/faces.csv", out.model.mesh, out.table);
    if (!faces.ok()) return fail(faces.status(), kExitFailure);
    out.faces = std::move(*faces);
    out.origin = "folder " + args.source;
    return out;
  }
  if (args.truth.empty())
    return fail(
        Status::InvalidArgument(args.source + " is not a folder; for a model file give its ground truth with --truth"),
        kExitUsage);
  ImportArgs import;
  import.no_textures = !args.textures;
  Result<Model> model = load_with_flags(command, args.source, import, exit_code);
  if (!model.ok()) return model.status();
  out.model = std::move(*model);
  Result<MaterialTable> table = load_table_flag(command, args.materials, exit_code);
  if (!table.ok()) return table.status();
  out.table = std::move(*table);
  Result<std::string> truth = read_text(args.truth);
  if (!truth.ok()) return fail(truth.status(), kExitFailure);
  const std::string key = args.key.empty() ? fs::path(args.source).stem().string() : args.key;
  Result<std::vector<int>> by_material =
      material_labels_from_json(*truth, key, out.table, static_cast<int>(out.model.materials.size()));
  if (!by_material.ok()) return fail(by_material.status().with_context(args.truth), kExitFailure);
  // Faces of materials without a class ("ignore") take their neighbours'
  // labels, as unseen faces do in the project stage: one vote per labelled face.
  const Mesh& mesh = out.model.mesh;
  FaceVotes votes;
  votes.num_classes = out.table.size();
  votes.row.assign(static_cast<std::size_t>(mesh.num_faces()), -1);
  votes.total.assign(static_cast<std::size_t>(mesh.num_faces()), 0.f);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int m = mesh.face_source.empty() ? -1 : mesh.face_source[static_cast<std::size_t>(f)].material;
    const int label = m >= 0 && m < static_cast<int>(by_material->size()) ? (*by_material)[static_cast<std::size_t>(m)]
                                                                          : kUnknownLabel;
    if (label == kUnknownLabel) continue;
    votes.row[static_cast<std::size_t>(f)] = static_cast<int>(votes.histogram.size() / votes.num_classes);
    votes.histogram.resize(votes.histogram.size() + static_cast<std::size_t>(votes.num_classes), 0.f);
    votes.histogram[votes.histogram.size() - static_cast<std::size_t>(votes.num_classes) + label] = 1.f;
    votes.total[static_cast<std::size_t>(f)] = 1.f;
  }
  Result<FaceGraph> graph = build_face_graph(mesh);
  if (!graph.ok()) return fail(graph.status(), kExitFailure);
  out.faces.labels = assign_labels(mesh, *graph, votes).label;
  out.faces.parts = partition(mesh, *graph, out.faces.labels, out.faces.face_part);
  out.origin = "ground truth '" + key + "' of " + args.truth;
  return out;
}

Result<BackendSettings> parse_settings(const std::vector<std::string>& pairs) {
  BackendSettings s;
  for (const std::string& p : pairs) {
    const std::size_t eq = p.find('=');
    if (eq == std::string::npos || eq == 0) return Status::InvalidArgument("expected KEY=VALUE, got '" + p + "'");
    s[p.substr(0, eq)] = p.substr(eq + 1);
  }
  return s;
}

void add_estimator_flags(CLI::App* cmd, EstimatorArgs& args) {
  cmd->add_option("--estimator", args.name, "Stage 6 backend: table (default) or vlm");
  cmd->add_option("--estimate-set", args.settings,
                  "Estimator setting KEY=VALUE (repeatable), e.g. model=qwen2.5-vl url=http://host/v1");
}

Result<PropertiesReport> run_estimation(const std::string& command, const EstimatorArgs& args,
                                        const LabelledObject& object, const Completion& completion, int& exit_code) {
  Result<BackendSettings> settings = parse_settings(args.settings);
  if (!settings.ok()) {
    std::cerr << "g2p " << command << ": error: --estimate-set: " << settings.status().message() << "\n";
    exit_code = kExitUsage;
    return settings.status();
  }
  Result<std::unique_ptr<PropertyEstimator>> estimator = make_estimator(args.name, *settings);
  if (!estimator.ok()) {
    std::cerr << "g2p " << command << ": error: " << estimator.status().to_string() << "\n";
    exit_code = kExitUsage;
    return estimator.status();
  }
  Result<PropertiesReport> report =
      estimate_properties(object.model.mesh, object.faces.parts, completion, object.table, **estimator);
  if (!report.ok()) {
    std::cerr << "g2p " << command << ": error: " << report.status().to_string() << "\n";
    exit_code = kExitFailure;
  }
  return report;
}

void add_completer_flags(CLI::App* cmd, CompleterArgs& args) {
  cmd->add_option("--completer", args.name,
                  "Stage 5 backend: partition (default), external, alpha-wrap and fill (CGAL builds)");
  cmd->add_option("--complete-set", args.settings, "Completer setting KEY=VALUE (repeatable), e.g. resolution=200");
  cmd->add_option("--fallback", args.fallback, "Backend for parts the completer fails, or 'none' (default partition)");
}

Result<Completion> run_completion(const std::string& command, const CompleterArgs& args, const LabelledObject& object,
                                  int& exit_code) {
  auto fail = [&](const Status& s, int code) -> Status {
    std::cerr << "g2p " << command << ": error: " << s.to_string() << "\n";
    exit_code = code;
    return s;
  };
#if defined(G2P_CLI_WITH_CGAL)
  if (Status s = register_cgal_completers(); !s.ok()) return fail(s, kExitFailure);
#endif
  Result<BackendSettings> settings = parse_settings(args.settings);
  if (!settings.ok()) return fail(settings.status().with_context("--complete-set"), kExitUsage);
  Result<std::unique_ptr<Completer>> completer = make_completer(args.name, *settings);
  if (!completer.ok()) return fail(completer.status(), kExitUsage);
  std::unique_ptr<Completer> fallback;
  if (args.fallback != "none" && args.fallback != args.name) {
    Result<std::unique_ptr<Completer>> f = make_completer(args.fallback);
    if (!f.ok()) return fail(f.status().with_context("--fallback"), kExitUsage);
    fallback = std::move(*f);
  }
  const auto start = std::chrono::steady_clock::now();
  CompletionInput input{&object.model.mesh, &object.faces.parts, &object.table};
  Result<Completion> done = complete(input, **completer, fallback.get());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!done.ok()) return fail(done.status(), kExitFailure);
  std::cout << "completed " << done->parts.size() << " parts of " << object.origin << " with '" << args.name << "' in "
            << std::fixed << std::setprecision(2) << seconds << " s\n";
  for (const std::string& n : done->notes) std::cout << "  " << n << "\n";
  for (const CompletedPart& p : done->parts) {
    const std::string name = object.table.valid_label(p.label) ? object.table[p.label].name : "Unknown";
    std::cout << "  part " << p.part << " " << name << ": " << (p.ok ? "ok" : "FAILED") << ", " << std::setprecision(6)
              << p.checks.volume_m3 * 1e6 << " cm^3, " << p.mesh.num_faces() << " triangles (" << p.backend << ")";
    for (const std::string& n : p.notes) std::cout << "; " << n;
    std::cout << "\n";
  }
  std::cout << "  object " << done->object_volume_m3 * 1e6 << " cm^3, parts sum " << done->parts_volume_m3 * 1e6
            << " cm^3\n";
  std::cout.unsetf(std::ios::floatfield);
  return done;
}

}  // namespace g2p::cli
