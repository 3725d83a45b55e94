// Reading an output folder back into the state of a run (Pipeline::resume),
// and a labelled object from ground truth.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "g2p/folder.h"
#include "g2p/io.h"
#include "g2p/overrides.h"
#include "g2p/render.h"
#include "g2p/segment.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

Result<std::string> read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Result<nlohmann::json> read_json(const std::string& path) {
  Result<std::string> text = read_text(path);
  if (!text.ok()) return text.status();
  nlohmann::json j = nlohmann::json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return Status::ParseError(path + ": not JSON");
  return j;
}

std::string view_file(const std::string& dir, std::size_t i, const char* what) {
  char name[64];
  std::snprintf(name, sizeof(name), "/view_%02zu_%s.png", i, what);
  return dir + name;
}

// The model as the run read it: the same import options, then the kind's size.
Result<Model> load_recorded_model(const FolderManifest& m, const ImportOptions& base) {
  ImportOptions io = base;
  io.unit_scale = m.import.unit_scale;
  io.height_m = m.import.height_m;
  io.longest_side_m = m.import.longest_side_m;
  io.up_axis = m.import.up_axis;
  io.z_up = m.import.z_up;
  io.load_textures = m.import.load_textures;
  io.strict = m.import.strict;
  Result<Model> model = load_model(m.model, io);
  if (!model.ok()) return model.status().with_context("the folder's model");
  if (m.kind_scale != 1.0) {  // as the identify step scaled it (a normalised mesh given its kind's size)
    for (Eigen::Vector3f& p : model->mesh.positions) p = (p.cast<double>() * m.kind_scale).cast<float>();
    model->info.unit_scale_m *= m.kind_scale;
    model->info.file_to_model.topLeftCorner<3, 3>() *= m.kind_scale;
    model->info.scale_source = "kind";
  }
  model->info.warnings = m.import_warnings;
  if (m.anonymize_names) anonymize_names(*model);
  if (m.base_color_only) reduce_to_base_color(*model);
  return model;
}

// views/ and segmented/: cameras, colours, face IDs and the segmenter's labels.
Status read_views(const std::string& dir, const Mesh& mesh, PipelineResult& r) {
  const std::string view_dir = dir + "/views";
  Result<std::string> cameras_text = read_text(view_dir + "/cameras.json");
  if (!cameras_text.ok()) return cameras_text.status();
  Result<std::vector<Camera>> cameras = cameras_from_json(*cameras_text);
  if (!cameras.ok()) return cameras.status().with_context(view_dir + "/cameras.json");
  r.views.assign(cameras->size(), View{});
  r.label_maps.assign(cameras->size(), LabelMap{});
  for (std::size_t i = 0; i < cameras->size(); ++i) {
    View& v = r.views[i];
    v.camera = (*cameras)[i];
    Result<ImageU8> ids = read_image(view_file(view_dir, i, "faceid"));
    Result<ImageI32> face_id = ids.ok() ? decode_face_ids(*ids) : Result<ImageI32>(ids.status());
    Result<ImageU8> rgba = read_image(view_file(view_dir, i, "rgb"));
    Result<ImageU8> index = read_image(view_file(dir + "/segmented", i, "labels_index"));
    for (const Status& s : {face_id.status(), rgba.status(), index.status()})
      if (!s.ok()) return s;
    v.face_id = std::move(*face_id);
    for (int f : v.face_id.storage())
      if (f >= mesh.num_faces())
        return Status::InvalidArgument(view_file(view_dir, i, "faceid") +
                                       ": face IDs do not belong to the folder's model (was the model file changed?)");
    v.rgb = ImageU8(rgba->width(), rgba->height(), 3);
    for (int y = 0; y < rgba->height(); ++y)
      for (int x = 0; x < rgba->width(); ++x)
        for (int c = 0; c < 3; ++c) v.rgb.at(x, y, c) = rgba->at(x, y, c);
    ImageI32& labels = r.label_maps[i].labels;
    labels = ImageI32(index->width(), index->height(), 1, kUnknownLabel);
    for (int y = 0; y < index->height(); ++y)
      for (int x = 0; x < index->width(); ++x) {
        const int l = index->at(x, y, 0);
        labels.at(x, y) = l == 255 ? kUnknownLabel : l;
      }
  }
  r.image_decided.assign(static_cast<std::size_t>(mesh.num_faces()), 0);
  Result<std::string> decided = read_text(dir + "/segmented/image_decided.csv");
  if (!decided.ok()) return Status::Ok();  // a folder without: no face was decided from the image alone
  std::istringstream lines(*decided);
  std::string line;
  std::getline(lines, line);  // header
  while (std::getline(lines, line)) {
    long first = -1, last = -1;
    if (std::sscanf(line.c_str(), "%ld,%ld", &first, &last) != 2 || first < 0 || last < first ||
        last >= mesh.num_faces())
      return Status::ParseError(dir + "/segmented/image_decided.csv: bad range '" + line + "'");
    for (long f = first; f <= last; ++f) r.image_decided[static_cast<std::size_t>(f)] = 1;
  }
  return Status::Ok();
}

// refine.json back as the refine stage's report.
void read_refine_report(const std::string& dir, PipelineResult& r) {
  Result<nlohmann::json> j = read_json(dir + "/refine.json");
  if (!j.ok() || !j->is_object() || j->value("refiner", "none") == "none") return;
  StageReport report;
  report.stage = Stage::kRefine;
  report.backend = j->value("refiner", "");
  if (j->contains("error") && (*j)["error"].is_string()) {
    report.ok = false;
    report.error = (*j)["error"].get<std::string>();
  }
  if (j->contains("notes") && (*j)["notes"].is_array())
    for (const nlohmann::json& n : (*j)["notes"])
      if (n.is_string()) report.notes.push_back(n.get<std::string>());
  r.stages.push_back(std::move(report));
}

// completed/: the closed parts.
Status read_completion(const std::string& dir, PipelineResult& r) {
  Result<nlohmann::json> doc = read_json(dir + "/completed/completion.json");
  if (!doc.ok()) return doc.status();
  const std::size_t np = r.projection.parts.size();
  try {
    const nlohmann::json& parts = doc->at("parts");
    if (parts.size() != np)
      return Status::InvalidArgument(dir + "/completed/completion.json: " + std::to_string(parts.size()) +
                                     " parts, and faces.csv has " + std::to_string(np));
    r.completion = Completion{};
    r.completion.object_volume_m3 = doc->at("object_volume_m3").get<double>();
    r.completion.grid_spacing_m = doc->value("grid_spacing_m", 0.0);
    r.completion.input_volume_m3 = doc->value("input_volume_m3", -1.0);
    r.completion.kept_parts = doc->value("kept_parts", 0);
    r.completion.notes = doc->value("notes", std::vector<std::string>{});
    for (std::size_t i = 0; i < np; ++i) {
      const nlohmann::json& c = parts[i];
      CompletedPart part;
      part.part = static_cast<int>(i);
      part.label = r.projection.parts[i].label;
      part.backend = c.at("backend").get<std::string>();
      part.ok = c.at("ok").get<bool>();
      if (c.at("files").contains("obj")) {
        ImportOptions io;
        io.z_up = false;
        io.unit_scale = 1.0;
        io.up_axis = UpAxis::kZ;
        io.load_textures = false;
        Result<Model> m = load_model(dir + "/completed/" + c["files"]["obj"].get<std::string>(), io);
        if (!m.ok()) return m.status();
        part.mesh.positions = std::move(m->mesh.positions);
        part.mesh.triangles = std::move(m->mesh.triangles);
      }
      part.checks.volume_m3 = c.at("checks").at("volume_m3").get<double>();
      part.checks.area_m2 = c.at("checks").at("area_m2").get<double>();
      part.input_volume_m3 = c.value("input_volume_m3", -1.0);
      if (c.contains("volume_difference") && c["volume_difference"].is_number())
        part.volume_difference = c["volume_difference"].get<double>();
      part.notes = c.value("notes", std::vector<std::string>{});
      r.completion.parts_volume_m3 += part.checks.volume_m3;
      r.completion.parts.push_back(std::move(part));
    }
    r.completion.parts_volume_m3 = doc->value("parts_volume_m3", r.completion.parts_volume_m3);
  } catch (const nlohmann::json::exception& e) {
    return Status::ParseError(dir + "/completed/completion.json: " + e.what());
  }
  return Status::Ok();
}

ValueSource source_from(const std::string& name) {
  for (ValueSource v :
       {ValueSource::kTable, ValueSource::kGeometry, ValueSource::kVlm, ValueSource::kUser, ValueSource::kKind})
    if (name == to_string(v)) return v;
  return ValueSource::kTable;
}

// report.json: the properties, per part as the properties stage gave them.
Status read_properties(const std::string& dir, PipelineResult& r) {
  const std::string path = dir + "/report.json";
  Result<nlohmann::json> report = read_json(path);
  if (!report.ok()) return report.status();
  const std::size_t np = r.projection.parts.size();
  try {
    const nlohmann::json& parts = report->at("parts");
    if (parts.size() != np)
      return Status::InvalidArgument(path + ": " + std::to_string(parts.size()) + " parts, and faces.csv has " +
                                     std::to_string(np));
    r.properties = PropertiesReport{};
    for (std::size_t i = 0; i < np; ++i) {
      const nlohmann::json& j = parts[i];
      const int label = r.projection.parts[i].label;
      const std::string is = r.table.valid_label(label) ? r.table[label].name : "Unknown";
      if (j.contains("material") && j["material"].is_string() && j["material"] != is)
        return Status::InvalidArgument(path + ": part " + std::to_string(i) + " is " + is + " by faces.csv but " +
                                       j["material"].get<std::string>() +
                                       " in report.json (changed after the properties stage?); run g2p properties "
                                       "on the folder again");
      PartReport pr;
      pr.part = static_cast<int>(i);
      pr.completed_ok = j.at("completion_ok").get<bool>();
      PartProperties& p = pr.properties;
      p.label = label;
      p.density_kg_m3 = j.at("density_kg_m3").get<double>();
      p.density_min_kg_m3 = j.at("density_min_kg_m3").get<double>();
      p.density_max_kg_m3 = j.at("density_max_kg_m3").get<double>();
      p.structure = j.at("structure").get<std::string>() == "hollow" ? Structure::kHollow : Structure::kSolid;
      if (!j.at("wall_thickness_m").is_null()) p.wall_thickness_m = j["wall_thickness_m"].get<double>();
      p.double_walled = j.value("double_walled", false);
      p.friction_static = j.at("friction_static").get<double>();
      p.friction_dynamic = j.at("friction_dynamic").get<double>();
      p.restitution = j.at("restitution").get<double>();
      for (int k = 0; k < 2; ++k) p.solref[static_cast<std::size_t>(k)] = j.at("mujoco_solref")[k].get<double>();
      for (int k = 0; k < 5; ++k) p.solimp[static_cast<std::size_t>(k)] = j.at("mujoco_solimp")[k].get<double>();
      if (j.contains("notes") && j["notes"].is_array())
        for (const nlohmann::json& n : j["notes"])
          if (n.is_string()) p.notes.push_back(n.get<std::string>());
      const nlohmann::json& sources = j.at("sources");
      p.density_source = source_from(sources.at("density").get<std::string>());
      p.structure_source = source_from(sources.at("structure").get<std::string>());
      p.thickness_source = source_from(sources.at("wall_thickness").get<std::string>());
      p.contact_source = source_from(sources.at("contact").get<std::string>());
      const nlohmann::json& walls = j.at("walls");
      p.walls.rays = walls.at("rays").get<int>();
      p.walls.inner_hits = static_cast<int>(std::lround(walls.at("inner_fraction").get<double>() * p.walls.rays));
      p.walls.thickness_m = walls.at("median_thickness_m").get<double>();
      p.walls.inner_wall_m = walls.at("median_inner_wall_m").get<double>();
      pr.mass.mass_kg = j.at("mass_kg").get<double>();
      pr.mass.volume_m3 = j.at("material_volume_m3").get<double>();
      if (j.contains("contents") && j["contents"].is_object()) {
        const nlohmann::json& c = j["contents"];
        p.contents_density_kg_m3 = c.at("density_kg_m3").get<double>();
        p.contents_fill = c.at("fill").get<double>();
        pr.contents.mass_kg = c.at("mass_kg").get<double>();
        pr.contents.volume_m3 = c.at("volume_m3").get<double>();
        for (int a = 0; a < 3; ++a) pr.contents.center_of_mass[a] = c.at("center_of_mass_m")[a].get<double>();
        pr.mass.volume_m3 += pr.contents.volume_m3;  // the part's mass holds both
      }
      pr.mass.area_m2 = j.at("area_m2").get<double>();
      for (int a = 0; a < 3; ++a) {
        pr.mass.center_of_mass[a] = j.at("center_of_mass_m")[a].get<double>();
        for (int b = 0; b < 3; ++b) pr.mass.inertia(a, b) = j.at("inertia_kg_m2")[a][b].get<double>();
      }
      pr.mass_min_kg = j.at("mass_min_kg").get<double>();
      pr.mass_max_kg = j.at("mass_max_kg").get<double>();
      r.properties.parts.push_back(std::move(pr));
    }
    if (report->contains("notes") && (*report)["notes"].is_array())
      for (const nlohmann::json& n : (*report)["notes"])
        if (n.is_string()) r.properties.notes.push_back(n.get<std::string>());
    r.properties.mass_min_kg = report->at("object").value("mass_min_kg", 0.0);
    r.properties.mass_max_kg = report->at("object").value("mass_max_kg", 0.0);
  } catch (const nlohmann::json::exception& e) {
    return Status::ParseError(path + ": " + e.what());
  }
  std::vector<MassProperties> masses;
  for (const PartReport& p : r.properties.parts)
    if (p.mass.mass_kg > 0) masses.push_back(p.mass);
  if (masses.empty()) return Status::InvalidArgument(path + ": no part has a mass");
  r.properties.object = combine(masses);
  r.properties.size = object_size(r.model);
  return Status::Ok();
}

Stage next(Stage s) { return static_cast<Stage>(static_cast<int>(s) + 1); }

}  // namespace

Result<FolderState> read_pipeline_folder(const std::string& dir, Stage first, const ImportOptions& import) {
  FolderState out;
  Result<FolderManifest> manifest = read_folder_manifest(dir);
  if (!manifest.ok()) return manifest.status();
  out.manifest = std::move(*manifest);
  const FolderManifest& m = out.manifest;
  if (m.stage < Stage::kProject)
    return Status::InvalidArgument(dir + ": holds the stages up to " + to_string(m.stage) +
                                   " (views and label maps, no face labels); the stage commands start from a folder "
                                   "of g2p project or g2p run");
  if (first < Stage::kRefine) first = Stage::kRefine;
  // A stage whose input the folder lacks runs again.
  if (first > next(m.stage)) {
    out.notes.push_back(std::string("the folder holds the stages up to ") + to_string(m.stage) + ": resumed at " +
                        to_string(next(m.stage)) + ", not " + to_string(first));
    first = next(m.stage);
  }
  std::error_code ec;
  if (first > Stage::kComplete && !fs::exists(dir + "/completed/completion.json", ec)) {
    out.notes.push_back(
        "the folder keeps no closed parts (g2p run keeps them with --save-intermediates): the parts are closed "
        "again");
    first = Stage::kComplete;
  }
  out.first = first;

  PipelineResult& r = out.result;
  Result<Model> model = load_recorded_model(m, import);
  if (!model.ok()) return model.status().with_context(dir);
  r.model = std::move(*model);
  const Mesh& mesh = r.model.mesh;
  if (m.materials.empty()) {
    r.table = MaterialTable::paper_default();
  } else {
    Result<MaterialTable> table = MaterialTable::load(dir + "/" + m.materials);
    if (!table.ok()) return table.status();
    r.table = std::move(*table);
  }
  r.identification = m.identification;
  if (!m.kind.empty()) {
    const int k = ObjectTable::shipped().find(m.kind);
    if (k < 0) return Status::InvalidArgument(dir + "/manifest.json: unknown kind '" + m.kind + "'");
    r.kind = ObjectTable::shipped().kinds()[static_cast<std::size_t>(k)];
  }
  r.size_assumed_m = m.size_assumed_m;
  r.kind_scale = m.kind_scale;

  if (fs::exists(dir + "/views/cameras.json", ec)) {
    G2P_RETURN_IF_ERROR(read_views(dir, mesh, r));
  } else if (first == Stage::kRefine) {
    return Status::InvalidArgument(dir + ": has no views (views/cameras.json), which the refine stage needs");
  }
  if (first == Stage::kRefine) {
    // The votes again from the label maps (every step is deterministic);
    // probabilities and depth are not kept, so the votes are hard and unweighted by footprint.
    ProjectOptions options = m.project;
    if (options.vote.mode == VoteMode::kSoft || options.vote.weight_by_footprint)
      out.notes.push_back(
          "the folder keeps label indices, not probabilities or depth: its votes are rebuilt as hard votes without "
          "footprint weights");
    options.vote.mode = VoteMode::kHard;
    options.vote.weight_by_footprint = false;
    Result<Projection> projection = project(mesh, r.views, r.label_maps, r.table.size(), options);
    if (!projection.ok()) return projection.status().with_context(dir);
    r.projection = std::move(*projection);
    r.projected_labels = r.projection.labels.label;
  } else {
    Result<FacesFile> faces = read_faces_csv(dir + "/faces.csv", mesh, r.table);
    if (!faces.ok()) return faces.status();
    Result<FaceGraph> graph = build_face_graph(mesh, m.project.weld_tolerance);
    if (!graph.ok()) return graph.status().with_context(dir);
    r.projection.graph = std::move(*graph);
    r.projection.labels.label = std::move(faces->labels);
    r.projection.labels.confidence.assign(r.projection.labels.label.size(), 0.f);
    r.projection.labels.seen.assign(r.projection.labels.label.size(), 0);
    r.projection.parts = std::move(faces->parts);
    r.projection.face_part = std::move(faces->face_part);
    read_refine_report(dir, r);
  }
  if (fs::exists(dir + "/overrides.json", ec)) {
    Result<Overrides> overrides = read_overrides(dir + "/overrides.json", r.table);
    if (!overrides.ok()) return overrides.status();
    r.overrides = std::move(*overrides);
  }
  // A folder whose corrections change classes its labels do not have (its
  // overrides.json edited after the fact) closes its parts again.
  if (first > Stage::kComplete && r.overrides.changes_labels()) {
    Result<ResolvedOverrides> resolved =
        resolve_overrides(r.overrides, mesh.num_faces(), r.projection.parts, r.projection.labels.label, r.table);
    if (!resolved.ok()) return resolved.status().with_context(dir + "/overrides.json");
    Projection applied = r.projection;
    Result<std::vector<std::string>> changed = apply_class_overrides(*resolved, mesh, applied, r.table);
    if (!changed.ok()) return changed.status().with_context(dir + "/overrides.json");
    if (applied.labels.label != r.projection.labels.label) {
      out.notes.push_back(
          "the folder's overrides.json changes classes its faces.csv does not have: the parts are "
          "closed again");
      out.first = first = Stage::kComplete;
    }
  }
  if (first > Stage::kComplete) G2P_RETURN_IF_ERROR(read_completion(dir, r));
  if (first > Stage::kProperties) {
    if (!fs::exists(dir + "/report.json", ec)) {
      out.notes.push_back("the folder has no report.json: the properties are estimated again");
      out.first = first = Stage::kProperties;
    } else {
      G2P_RETURN_IF_ERROR(read_properties(dir, r));
    }
  }
  r.last_stage = static_cast<Stage>(static_cast<int>(first) - 1);
  return out;
}

Result<PipelineResult> labelled_from_truth(const std::string& model_path, const std::string& truth_path,
                                           const std::string& key, const MaterialTable& table,
                                           const ImportOptions& import) {
  PipelineResult r;
  Result<Model> model = load_model(model_path, import);
  if (!model.ok()) return model.status();
  r.model = std::move(*model);
  r.table = table;
  Result<std::string> truth = read_text(truth_path);
  if (!truth.ok()) return truth.status();
  const std::string entry = key.empty() ? fs::path(model_path).stem().string() : key;
  Result<std::vector<int>> by_material =
      material_labels_from_json(*truth, entry, table, static_cast<int>(r.model.materials.size()));
  if (!by_material.ok()) return by_material.status().with_context(truth_path);
  // Faces of materials without a class ("ignore") take their neighbours'
  // labels, as unseen faces do in the project stage: one vote per labelled face.
  const Mesh& mesh = r.model.mesh;
  FaceVotes votes;
  votes.num_classes = table.size();
  votes.row.assign(static_cast<std::size_t>(mesh.num_faces()), -1);
  votes.total.assign(static_cast<std::size_t>(mesh.num_faces()), 0.f);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int mat = mesh.face_source.empty() ? -1 : mesh.face_source[static_cast<std::size_t>(f)].material;
    const int label = mat >= 0 && mat < static_cast<int>(by_material->size())
                          ? (*by_material)[static_cast<std::size_t>(mat)]
                          : kUnknownLabel;
    if (label == kUnknownLabel) continue;
    votes.row[static_cast<std::size_t>(f)] = static_cast<int>(votes.histogram.size() / votes.num_classes);
    votes.histogram.resize(votes.histogram.size() + static_cast<std::size_t>(votes.num_classes), 0.f);
    votes.histogram[votes.histogram.size() - static_cast<std::size_t>(votes.num_classes) + label] = 1.f;
    votes.total[static_cast<std::size_t>(f)] = 1.f;
  }
  Result<FaceGraph> graph = build_face_graph(mesh);
  if (!graph.ok()) return graph.status();
  r.projection.graph = std::move(*graph);
  r.projection.labels = assign_labels(mesh, r.projection.graph, votes);
  r.projection.parts = partition(mesh, r.projection.graph, r.projection.labels.label, r.projection.face_part);
  r.projected_labels = r.projection.labels.label;
  r.last_stage = Stage::kRefine;
  return r;
}

Result<std::array<double, 2>> truth_mass_range(const std::string& truth_path, const std::string& key) {
  Result<nlohmann::json> j = read_json(truth_path);
  if (!j.ok()) return j.status();
  const nlohmann::json* entry = j->contains("models") && (*j)["models"].contains(key) ? &(*j)["models"][key] : &*j;
  if (!entry->is_object() || !entry->contains("real_mass_kg") || !(*entry)["real_mass_kg"].is_array() ||
      (*entry)["real_mass_kg"].size() != 2 || !(*entry)["real_mass_kg"][0].is_number() ||
      !(*entry)["real_mass_kg"][1].is_number())
    return Status::NotFound(truth_path + ": '" + key + "' gives no real_mass_kg range");
  return std::array<double, 2>{(*entry)["real_mass_kg"][0].get<double>(), (*entry)["real_mass_kg"][1].get<double>()};
}

}  // namespace g2p
