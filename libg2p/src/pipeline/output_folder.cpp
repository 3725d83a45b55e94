// The pipeline's output folder, written beside its final place and renamed
// into it, and its machine-readable summary (run.json).
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/file_util.h"
#include "core/json_text.h"
#include "g2p/io.h"
#include "g2p/pipeline.h"
#include "pipeline/run_summary.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

nlohmann::json vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::string class_name(const MaterialTable& table, int label) {
  return table.valid_label(label) ? table[label].name : std::string("Unknown");
}

// project.json and properties.json: what `g2p refine/complete/export DIR`
// read to rebuild the labelled object from the model file.
Status write_manifests(const std::string& tmp, const fs::path& final_dir, const PipelineResult& r,
                       const PipelineOptions& o) {
  const ImportInfo& info = r.model.info;
  std::string materials;
  if (r.table.to_json() != MaterialTable::paper_default().to_json()) {
    G2P_RETURN_IF_ERROR(r.table.save(tmp + "/materials.json"));
    materials = (final_dir / "materials.json").string();
  }
  const bool rotated = !info.file_to_model.block<3, 3>(0, 0).isApprox(
      Eigen::Matrix3d::Identity() * info.file_to_model.block<3, 3>(0, 0).col(0).norm());
  char unit[32];
  std::snprintf(unit, sizeof unit, "%.17g", info.unit_scale_m);
  const std::string up(1, static_cast<char>(std::tolower(static_cast<unsigned char>(info.up_axis))));
  const nlohmann::json project = {
      {"format", "g2p-project"},
      {"version", 1},
      {"model", fs::absolute(info.path).string()},
      {"import", {{"unit", unit}, {"up", up}, {"keep_axes", !rotated && up != "z"}, {"no_textures", false}}},
      {"materials", materials},
      {"anonymize_names", o.anonymize_names},
      {"base_color_only", o.base_color_only},
      {"object", r.identification.known() ? r.identification.kind() : std::string()},
      {"views", r.views.size()},
      {"vote", o.project.vote.mode == VoteMode::kSoft ? "soft" : "hard"},
      {"weight_angle", o.project.vote.weight_by_angle},
      {"weight_footprint", o.project.vote.weight_by_footprint},
      {"weld", o.project.weld_tolerance},
      {"min_part_area", o.project.partition.min_part_area_fraction},
      {"written_by", "g2p run"}};
  G2P_RETURN_IF_ERROR(write_text_file(tmp + "/project.json", detail::json_text(project, 2) + "\n"));
  const nlohmann::json properties = {{"format", "g2p-properties"},
                                     {"version", 1},
                                     {"source", final_dir.string()},
                                     {"truth", ""},
                                     {"key", ""},
                                     {"materials", materials},
                                     {"written_by", "g2p run"}};
  return write_text_file(tmp + "/properties.json", detail::json_text(properties, 2) + "\n");
}

// intermediates/: per-face votes and part patches (the per-view class
// probabilities go beside the label maps, segmented/view_XX_probs.npy).
Status write_intermediates(const std::string& dir, const PipelineResult& r) {
  G2P_RETURN_IF_ERROR(detail::ensure_directory(dir));
  // votes.csv: face, total, then one column per class.
  std::ostringstream votes;
  votes << "face,total";
  for (const MaterialClass& c : r.table.classes()) votes << "," << c.name;
  votes << "\n";
  const FaceVotes& v = r.projection.votes;
  for (int f = 0; f < r.model.mesh.num_faces(); ++f) {
    votes << f << "," << v.total[static_cast<std::size_t>(f)];
    const float* h = v.of(f);
    for (int k = 0; k < v.num_classes; ++k) votes << "," << (h != nullptr ? h[k] : 0.f);
    votes << "\n";
  }
  G2P_RETURN_IF_ERROR(detail::write_file_atomically(dir + "/votes.csv", votes.str()));
  G2P_RETURN_IF_ERROR(detail::ensure_directory(dir + "/patches"));
  for (std::size_t i = 0; i < r.projection.parts.size(); ++i) {
    const Part& part = r.projection.parts[i];
    G2P_RETURN_IF_ERROR(
        write_mesh(dir + "/patches/part_" + std::to_string(i) + "_" + class_name(r.table, part.label) + ".obj",
                   part_patch(r.model.mesh, part)));
  }
  return Status::Ok();
}

Status write_contents(const std::string& tmp, const fs::path& final_dir, const PipelineResult& r,
                      const PipelineOptions& o, const OutputOptions& out) {
  ViewFileOptions views;
  views.buffers = out.intermediates;
  G2P_RETURN_IF_ERROR(write_views(tmp + "/views", r.views, views));
  if (out.intermediates) {
    G2P_RETURN_IF_ERROR(write_label_maps(tmp + "/segmented", r.label_maps, r.table));  // with view_XX_probs.npy
  } else {
    // The class probabilities (12 floats a pixel, 138 MB for 11 views at 512 px) are intermediates.
    std::vector<LabelMap> labels_only(r.label_maps.size());
    for (std::size_t i = 0; i < r.label_maps.size(); ++i) labels_only[i].labels = r.label_maps[i].labels;
    G2P_RETURN_IF_ERROR(write_label_maps(tmp + "/segmented", labels_only, r.table));
  }
  G2P_RETURN_IF_ERROR(write_projection(tmp, r.model, r.views, r.projection, r.table));
  const StageReport* refine = r.stage(Stage::kRefine);
  nlohmann::json refine_json = {{"refiner", refine != nullptr ? refine->backend : "none"}};
  if (refine != nullptr && !refine->ok) refine_json["error"] = refine->error;
  if (!r.refinement.labels.empty()) {
    refine_json["notes"] = r.refinement.notes;
    refine_json["changed_faces"] = r.refinement.changes.size();
  }
  G2P_RETURN_IF_ERROR(write_text_file(tmp + "/refine.json", detail::json_text(refine_json, 2) + "\n"));
  // The closed volumes can be dense (grid-based): only on request.
  if (out.intermediates) G2P_RETURN_IF_ERROR(write_completion(tmp + "/completed", r.completion, r.table, {"obj"}));
  std::vector<std::string> engine_formats;
  bool glb = false;
  for (const std::string& f : o.formats) {
    if (f == "glb")
      glb = true;
    else
      engine_formats.push_back(f);
  }
  G2P_RETURN_IF_ERROR(write_asset(tmp, r.asset, engine_formats, o.export_options));
  if (glb) G2P_RETURN_IF_ERROR(write_glb(tmp + "/" + r.asset.name + ".glb", r.model, r.projection.parts, r.asset));
  G2P_RETURN_IF_ERROR(write_asset_report(tmp + "/report.json", r.properties, r.asset, r.table));
  if (!r.model.info.path.empty()) G2P_RETURN_IF_ERROR(write_manifests(tmp, final_dir, r, o));
  if (out.intermediates) G2P_RETURN_IF_ERROR(write_intermediates(tmp + "/intermediates", r));
  // The corrections as face selections: the stages that start from this folder apply them.
  if (!r.overrides.empty())
    G2P_RETURN_IF_ERROR(write_text_file(tmp + "/overrides.json", overrides_json(r.overrides, r.table)));
  G2P_RETURN_IF_ERROR(write_text_file(tmp + "/run.json", pipeline_summary_json(r, o) + "\n"));
  return write_text_file(tmp + "/summary.html", summary_html(r, o));
}

}  // namespace

namespace {

// The output folder as an absolute path with "..", "." and links resolved:
// `-o ../X` run from inside X names X itself, whose parent is where the
// temporary and previous folders go.
fs::path final_folder(const std::string& dir) {
  std::error_code ec;
  fs::path target = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  if (ec) target = fs::absolute(fs::path(dir), ec).lexically_normal();
  return target.filename().empty() ? target.parent_path() : target;
}

// Whether `inner` is `folder` or lies below it (both absolute and normal).
bool lies_inside(const fs::path& inner, const fs::path& folder) {
  auto i = inner.begin();
  for (auto f = folder.begin(); f != folder.end(); ++f, ++i)
    if (i == inner.end() || *i != *f) return false;
  return true;
}

// What an existing folder may hold for --overwrite to replace it.
Status check_replaceable(const fs::path& folder, const OutputOptions& output) {
  std::error_code ec;
  if (!output.input_path.empty()) {
    const fs::path input = fs::weakly_canonical(fs::absolute(output.input_path, ec), ec);
    if (!ec && lies_inside(input, folder))
      return Status::InvalidArgument(folder.string() + ": holds the model being run (" + input.string() +
                                     "), which replacing the folder would delete; write the output elsewhere");
  }
  const fs::path cwd = fs::weakly_canonical(fs::current_path(ec), ec);
  if (!ec && lies_inside(cwd, folder))
    return Status::InvalidArgument(folder.string() +
                                   ": is or holds the working directory, which replacing it would delete; "
                                   "write the output elsewhere");
  if (fs::is_empty(folder, ec)) return Status::Ok();
  for (const char* mark : {"run.json", "report.json", "project.json"})
    if (fs::exists(folder / mark, ec)) return Status::Ok();
  return Status::InvalidArgument(folder.string() +
                                 ": exists and is not a g2p output folder (no run.json, report.json or "
                                 "project.json), so it is not replaced; choose a new folder");
}

}  // namespace

Status check_output_folder(const std::string& dir, const OutputOptions& output) {
  if (dir.empty()) return Status::InvalidArgument("no output folder given");
  std::error_code ec;
  const fs::path final_dir = final_folder(dir);
  if (fs::exists(final_dir, ec) && !fs::is_directory(final_dir, ec))
    return Status::InvalidArgument(final_dir.string() + ": exists and is not a folder");
  if (fs::exists(final_dir, ec) && !output.overwrite)
    return Status::InvalidArgument(final_dir.string() + ": exists; choose another folder or allow overwriting");
  if (fs::exists(final_dir, ec)) G2P_RETURN_IF_ERROR(check_replaceable(final_dir, output));
  fs::path above = final_dir.parent_path();
  while (!above.empty() && !fs::exists(above, ec) && above != above.parent_path()) above = above.parent_path();
  if (!fs::is_directory(above, ec))
    return Status::InvalidArgument(above.string() + ": is not a folder, so " + final_dir.string() + " cannot be made");
  // Permissions alone do not tell (root, read-only mounts, pseudo file
  // systems): make and remove an empty folder where the output will go.
  std::string probe = (above / ".g2p-probe-XXXXXX").string();
  if (::mkdtemp(probe.data()) == nullptr)
    return Status::IoError(above.string() + ": cannot write here (" + std::strerror(errno) + "), so " +
                           final_dir.string() + " cannot be made");
  fs::remove(probe, ec);
  return Status::Ok();
}

Status write_pipeline_output(const std::string& dir, const PipelineResult& result, const PipelineOptions& options,
                             const OutputOptions& output) {
  if (dir.empty()) return Status::InvalidArgument("write_pipeline_output: no output folder given");
  if (result.views.empty() || result.asset.parts.empty())
    return Status::InvalidArgument("write_pipeline_output: the result is incomplete (did the run succeed?)");
  std::error_code ec;
  const fs::path final_dir = final_folder(dir);
  OutputOptions checked = output;
  if (checked.input_path.empty() && result.model.info.path != "<memory>") checked.input_path = result.model.info.path;
  G2P_RETURN_IF_ERROR(check_output_folder(dir, checked));
  const fs::path parent = final_dir.parent_path();
  G2P_RETURN_IF_ERROR(detail::ensure_directory(parent.string()));
  const std::string tag = "." + final_dir.filename().string() + ".g2p-" + std::to_string(::getpid());
  const fs::path tmp = parent / (tag + ".tmp");
  const fs::path old = parent / (tag + ".old");
  fs::remove_all(tmp, ec);
  Status s = detail::ensure_directory(tmp.string());
  if (s.ok()) s = write_contents(tmp.string(), final_dir, result, options, output);
  if (s.ok() && fs::exists(final_dir)) {
    fs::rename(final_dir, old, ec);
    if (ec) s = Status::IoError(final_dir.string() + ": cannot move the previous output aside: " + ec.message());
  }
  if (s.ok()) {
    fs::rename(tmp, final_dir, ec);
    if (ec) {
      s = Status::IoError(final_dir.string() + ": cannot move the new output into place: " + ec.message());
      std::error_code back;
      if (fs::exists(old)) {
        fs::rename(old, final_dir, back);  // the previous output stays as it was
        if (back) s = Status::IoError(s.message() + "; the previous output is kept at " + old.string());
      }
    }
  }
  if (!s.ok()) {
    fs::remove_all(tmp, ec);
    return s;
  }
  fs::remove_all(old, ec);
  return Status::Ok();
}

namespace detail {

nlohmann::json part_summary_json(const PipelineResult& r, std::size_t i) {
  const Part& p = r.projection.parts[i];
  nlohmann::json j = {
      {"part", i}, {"material", class_name(r.table, p.label)}, {"faces", p.faces.size()}, {"area_m2", p.area_m2}};
  if (i < r.completion.parts.size()) {
    j["closed"] = r.completion.parts[i].ok;
    j["volume_m3"] = r.completion.parts[i].checks.volume_m3;
  }
  if (i < r.properties.parts.size()) {
    const PartReport& pr = r.properties.parts[i];
    j["density_kg_m3"] = pr.properties.density_kg_m3;
    j["structure"] = to_string(pr.properties.structure);
    j["wall_thickness_m"] = pr.properties.wall_thickness_m;
    j["mass_kg"] = pr.mass.mass_kg;
    if (pr.contents.mass_kg > 0) {  // a filled hollow part: mass_kg holds the fill too
      j["contents_fill"] = pr.properties.contents_fill;
      j["contents_mass_kg"] = pr.contents.mass_kg;
    }
  }
  return j;
}

}  // namespace detail

std::string pipeline_summary_json(const PipelineResult& r, const PipelineOptions& o) {
  nlohmann::json stages = nlohmann::json::array();
  nlohmann::json backends = nlohmann::json::object();
  for (const StageReport& s : r.stages) {
    backends[to_string(s.stage)] = s.backend;
    nlohmann::json j = {{"stage", to_string(s.stage)},
                        {"backend", s.backend},
                        {"seconds", s.seconds},
                        {"peak_rss_mib", static_cast<double>(s.peak_rss_bytes) / (1024.0 * 1024.0)},
                        {"ok", s.ok},
                        {"notes", s.notes}};
    if (!s.ok) j["error"] = s.error;
    stages.push_back(std::move(j));
  }
  nlohmann::json parts = nlohmann::json::array();
  for (std::size_t i = 0; i < r.projection.parts.size(); ++i) parts.push_back(detail::part_summary_json(r, i));
  const MassProperties& m = r.properties.object;
  std::vector<std::string> files;
  for (const std::string& f : o.formats) {
    if (f == "mjcf") files.push_back(r.asset.name + ".xml");
    if (f == "urdf") files.push_back(r.asset.name + ".urdf");
    if (f == "sdf") files.push_back(r.asset.name + ".sdf");
    if (f == "glb") files.push_back(r.asset.name + ".glb");
  }
  nlohmann::json identification =
      r.asset.identification_json.empty()
          ? nlohmann::json(nullptr)
          : nlohmann::json::parse(r.asset.identification_json, nullptr, /*allow_exceptions=*/false);
  if (identification.is_object()) {
    const bool known = !r.kind.name.empty() && m.mass_kg > 0;
    identification["mass_in_kind_range"] =
        known ? nlohmann::json(m.mass_kg >= r.kind.mass_kg[0] && m.mass_kg <= r.kind.mass_kg[1])
              : nlohmann::json(nullptr);
  }
  const nlohmann::json j = {{"format", "g2p-run"},
                            {"version", 1},
                            {"model", r.model.info.path},
                            {"name", r.asset.name},
                            {"triangles", r.model.mesh.num_faces()},
                            {"views", r.views.size()},
                            {"backends", backends},
                            {"stages", stages},
                            {"seconds", r.seconds},
                            {"peak_rss_mib", static_cast<double>(r.peak_rss_bytes) / (1024.0 * 1024.0)},
                            {"parts", parts},
                            {"object",
                             {{"mass_kg", m.mass_kg},
                              {"mass_min_kg", r.properties.mass_min_kg},
                              {"mass_max_kg", r.properties.mass_max_kg},
                              {"center_of_mass_m", vec3(m.center_of_mass)}}},
                            {"identification", identification},
                            {"assets", files},
                            {"overrides", r.overrides_applied},
                            {"warnings", r.warnings}};
  return detail::json_text(j, 2);
}

}  // namespace g2p
