#include "stage_inputs.h"

#include "g2p/identify.h"
#include "json_out.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "g2p/io.h"
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
  add_overrides_flag(cmd, args.overrides);
}

namespace {
Result<LabelledObject> load_labels(const std::string& command, const LabelledSourceArgs& args, int& exit_code);
}  // namespace

Result<LabelledObject> load_labelled_source(const std::string& command, const LabelledSourceArgs& args,
                                            int& exit_code) {
  Result<LabelledObject> out = load_labels(command, args, exit_code);
  if (!out.ok()) return out;
  std::vector<std::pair<std::string, bool>> files;  // path, carried
  if (args.folder_overrides && std::filesystem::is_directory(args.source) &&
      std::filesystem::exists(args.source + "/overrides.json"))
    files.emplace_back(args.source + "/overrides.json", true);
  if (!args.overrides.empty()) files.emplace_back(args.overrides, args.overrides_carried);
  for (const auto& [f, carried] : files)
    G2P_RETURN_IF_ERROR(
        apply_overrides_file(command, f, out->model.mesh, out->table, out->faces, out->overrides, exit_code, carried));
  finish_overrides(out->model.mesh.num_faces(), out->faces.parts, out->faces.labels, out->table, out->overrides);
  if (!out->overrides.combined.object.empty()) {  // a correction of what the object is (checked when read)
    Result<std::string> kind = kind_from_text(ObjectTable::shipped(), out->overrides.combined.object);
    if (kind.ok()) out->kind = *kind;
  }
  for (const std::string& n : out->overrides.notes) std::cout << "correction: " << n << "\n";
  return out;
}

namespace {

Result<LabelledObject> load_labels(const std::string& command, const LabelledSourceArgs& args, int& exit_code) {
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
    // The model as the run saw it (g2p run --anonymize-names, --base-color-only).
    if (manifest.value("anonymize_names", false)) anonymize_names(*model);
    if (manifest.value("base_color_only", false)) reduce_to_base_color(*model);
    out.model = std::move(*model);
    const std::string table_path = args.materials.empty() ? manifest.value("materials", "") : args.materials;
    Result<MaterialTable> table = load_table_flag(command, table_path, exit_code);
    if (!table.ok()) return table.status();
    out.table = std::move(*table);
    Result<FacesFile> faces = read_faces_csv(args.source + "/faces.csv", out.model.mesh, out.table);
    if (!faces.ok()) return fail(faces.status(), kExitFailure);
    out.faces = std::move(*faces);
    out.origin = "folder " + args.source;
    out.kind = manifest.value("object", "");
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

}  // namespace

Status write_properties_manifest(const std::string& out, const LabelledSourceArgs& source) {
  namespace fs = std::filesystem;
  const nlohmann::json j = {{"format", "g2p-properties"},
                            {"version", 1},
                            {"source", fs::absolute(source.source).string()},
                            {"truth", source.truth.empty() ? "" : fs::absolute(source.truth).string()},
                            {"key", source.key},
                            {"materials", source.materials.empty() ? "" : fs::absolute(source.materials).string()}};
  return write_text_file(out + "/properties.json", json_out(j) + "\n");
}

bool is_properties_folder(const std::string& dir) {
  // A `g2p run` folder holds completed/ only with --save-intermediates;
  // without it, the closed parts are made again from its labels.
  return std::filesystem::exists(dir + "/properties.json") && std::filesystem::exists(dir + "/report.json") &&
         std::filesystem::exists(dir + "/completed/completion.json");
}

Result<PropertiesOutput> load_properties_output(const std::string& command, const std::string& dir, int& exit_code) {
  auto fail = [&](const Status& s) -> Status {
    std::cerr << "g2p " << command << ": error: " << s.to_string() << "\n";
    exit_code = kExitFailure;
    return s;
  };
  auto parse = [&](const std::string& path) -> Result<nlohmann::json> {
    Result<std::string> text = read_text(path);
    if (!text.ok()) return text.status();
    nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
    if (j.is_discarded()) return Status::ParseError(path + ": not JSON");
    return j;
  };
  Result<nlohmann::json> manifest = parse(dir + "/properties.json");
  if (!manifest.ok()) return fail(manifest.status());
  LabelledSourceArgs source;
  source.source = manifest->value("source", "");
  source.truth = manifest->value("truth", "");
  source.key = manifest->value("key", "");
  source.materials = manifest->value("materials", "");
  source.textures = true;
  // The corrections this folder was made with: they hold the source folder's
  // own, so those are not applied a second time.
  std::error_code same_error;
  if (std::filesystem::exists(dir + "/overrides.json") &&
      !std::filesystem::equivalent(source.source, dir, same_error)) {
    source.overrides = dir + "/overrides.json";
    source.overrides_carried = true;
    source.folder_overrides = false;
  }
  PropertiesOutput out;
  Result<LabelledObject> object = load_labelled_source(command, source, exit_code);
  if (!object.ok()) return object.status();
  out.object = std::move(*object);
  Result<nlohmann::json> completion = parse(dir + "/completed/completion.json");
  Result<nlohmann::json> report = parse(dir + "/report.json");
  if (!completion.ok()) return fail(completion.status());
  if (!report.ok()) return fail(report.status());
  const std::size_t np = out.object.faces.parts.size();
  if ((*completion)["parts"].size() != np || (*report)["parts"].size() != np)
    return fail(Status::InvalidArgument(dir + ": its parts do not match the source's " + std::to_string(np) +
                                        " parts (was the source changed?)"));
  // Each part's class too: `g2p complete --overrides` into the folder changes
  // completed/ but not report.json.
  for (std::size_t i = 0; i < np; ++i) {
    const int label = out.object.faces.parts[i].label;
    const std::string is = out.object.table.valid_label(label) ? out.object.table[label].name : "Unknown";
    const nlohmann::json& reported = (*report)["parts"][i];
    if (reported.contains("material") && reported["material"].is_string() && reported["material"] != is)
      return fail(Status::InvalidArgument(dir + ": part " + std::to_string(i) + " is " + is +
                                          " by its labels and corrections but " +
                                          reported["material"].get<std::string>() +
                                          " in report.json (changed after g2p properties?); run g2p properties on "
                                          "the folder again"));
  }
  try {
    out.completion.object_volume_m3 = (*completion)["object_volume_m3"].get<double>();
    for (std::size_t i = 0; i < np; ++i) {
      const nlohmann::json& c = (*completion)["parts"][i];
      CompletedPart part;
      part.part = static_cast<int>(i);
      part.label = out.object.faces.parts[i].label;
      part.backend = c["backend"].get<std::string>();
      part.ok = c["ok"].get<bool>();
      if (c["files"].contains("obj")) {
        ImportOptions io;
        io.z_up = false;
        io.unit_scale = 1.0;
        io.up_axis = UpAxis::kZ;
        io.load_textures = false;
        Result<Model> m = load_model(dir + "/completed/" + c["files"]["obj"].get<std::string>(), io);
        if (!m.ok()) return fail(m.status());
        part.mesh.positions = std::move(m->mesh.positions);
        part.mesh.triangles = std::move(m->mesh.triangles);
      }
      part.checks.volume_m3 = c["checks"]["volume_m3"].get<double>();
      part.checks.area_m2 = c["checks"]["area_m2"].get<double>();
      out.completion.parts.push_back(std::move(part));

      const nlohmann::json& r = (*report)["parts"][i];
      PartReport pr;
      pr.part = static_cast<int>(i);
      pr.completed_ok = r["completion_ok"].get<bool>();
      PartProperties& p = pr.properties;
      p.label = out.object.faces.parts[i].label;
      p.density_kg_m3 = r["density_kg_m3"].get<double>();
      p.density_min_kg_m3 = r["density_min_kg_m3"].get<double>();
      p.density_max_kg_m3 = r["density_max_kg_m3"].get<double>();
      p.structure = r["structure"].get<std::string>() == "hollow" ? Structure::kHollow : Structure::kSolid;
      if (!r["wall_thickness_m"].is_null()) p.wall_thickness_m = r["wall_thickness_m"].get<double>();
      p.double_walled = r.value("double_walled", false);
      p.friction_static = r["friction_static"].get<double>();
      p.friction_dynamic = r["friction_dynamic"].get<double>();
      p.restitution = r["restitution"].get<double>();
      for (int k = 0; k < 2; ++k) p.solref[static_cast<std::size_t>(k)] = r["mujoco_solref"][k].get<double>();
      for (int k = 0; k < 5; ++k) p.solimp[static_cast<std::size_t>(k)] = r["mujoco_solimp"][k].get<double>();
      pr.mass.mass_kg = r["mass_kg"].get<double>();
      pr.mass.volume_m3 = r["material_volume_m3"].get<double>();
      if (r.contains("contents") && r["contents"].is_object()) {
        const nlohmann::json& c = r["contents"];
        p.contents_density_kg_m3 = c["density_kg_m3"].get<double>();
        p.contents_fill = c["fill"].get<double>();
        pr.contents.mass_kg = c["mass_kg"].get<double>();
        pr.contents.volume_m3 = c["volume_m3"].get<double>();
        for (int a = 0; a < 3; ++a) pr.contents.center_of_mass[a] = c["center_of_mass_m"][a].get<double>();
        pr.mass.volume_m3 += pr.contents.volume_m3;  // the part's mass holds both
      }
      pr.mass.area_m2 = r["area_m2"].get<double>();
      for (int a = 0; a < 3; ++a) {
        pr.mass.center_of_mass[a] = r["center_of_mass_m"][a].get<double>();
        for (int b = 0; b < 3; ++b) pr.mass.inertia(a, b) = r["inertia_kg_m2"][a][b].get<double>();
      }
      pr.mass_min_kg = r["mass_min_kg"].get<double>();
      pr.mass_max_kg = r["mass_max_kg"].get<double>();
      out.report.parts.push_back(std::move(pr));
    }
  } catch (const nlohmann::json::exception& e) {
    return fail(Status::ParseError(dir + ": completion.json or report.json: " + e.what()));
  }
  std::vector<MassProperties> masses;
  for (const PartReport& r : out.report.parts)
    if (r.mass.mass_kg > 0) masses.push_back(r.mass);
  if (masses.empty()) return fail(Status::InvalidArgument(dir + "/report.json: no part has a mass"));
  out.report.object = combine(masses);
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
  // The vlm estimator looks at the object: the default views, rendered here.
  std::vector<View> views;
  if (args.name == "vlm") {
    Result<std::vector<View>> rendered = render_with_flags(command, object.model, ViewArgs{}, exit_code);
    if (!rendered.ok()) return rendered.status();
    views = std::move(*rendered);
  }
  std::unique_ptr<PropertyEstimator> overriding;
  if (object.overrides.resolved && object.overrides.changes_properties())
    overriding = make_overriding_estimator(**estimator, *object.overrides.resolved);
  // The kind the run identified weighs the object as g2p run did (its structure, its hidden mass).
  const ObjectTable& kinds = ObjectTable::shipped();
  const int kind = object.kind.empty() ? -1 : kinds.find(object.kind);
  const PropertyEstimator& chosen = overriding ? *overriding : **estimator;
  const std::vector<View>* seen = views.empty() ? nullptr : &views;
  Result<PropertiesReport> report =
      kind >= 0 ? estimate_properties_of_kind(object.model.mesh, object.faces.parts, completion, object.table, chosen,
                                              kinds.kinds()[static_cast<std::size_t>(kind)], seen)
                : estimate_properties(object.model.mesh, object.faces.parts, completion, object.table, chosen, seen);
  if (!report.ok()) {
    std::cerr << "g2p " << command << ": error: " << report.status().to_string() << "\n";
    exit_code = kExitFailure;
    return report;
  }
  report->size = object_size(object.model);
  for (const std::string& n : report->notes)  // asked for, not given: say so where it cannot be missed
    if (n.find(kContentsLeftOut) != std::string::npos) std::cerr << "g2p " << command << ": warning: " << n << "\n";
  return report;
}

void add_completer_flags(CLI::App* cmd, CompleterArgs& args) {
  cmd->add_option("--completer", args.name,
                  "Stage 5 backend: partition (default), external, alpha-wrap and fill (CGAL builds)");
  cmd->add_option("--complete-set", args.settings, "Completer setting KEY=VALUE (repeatable), e.g. resolution=200");
  cmd->add_option("--fallback", args.fallback, "Backend for parts the completer fails, or 'none' (default partition)");
}

void add_decomposer_flags(CLI::App* cmd, DecomposerArgs& args) {
  cmd->add_option("--decomposer", args.name,
                  "Collision geometry: voxel-cut (default: convex decomposition), hull (one convex hull per part)");
  cmd->add_option("--decompose-set", args.settings,
                  "Decomposer setting KEY=VALUE (repeatable), e.g. resolution=96 (voxel-cut: resolution, error, cuts)");
  cmd->add_option("--max-hulls", args.options.max_hulls, "Convex hulls per part at most (1-256, default 16)");
  cmd->add_option("--hull-vertices", args.options.max_vertices_per_hull,
                  "Vertices per convex hull at most (4-255, default 64; engines cap hulls at 255)");
  cmd->add_option(
      "--min-concavity", args.options.min_depth_m,
      "Leave concavities shallower than this alone, in metres (default 0: 1 % of the object's bounding-box diagonal)");
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
