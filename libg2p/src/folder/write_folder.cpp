// Writing the output folder: what a result holds, as far as its last stage
// went, committed atomically (folder/commit.h).
#include <algorithm>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/file_util.h"
#include "core/json_text.h"
#include "core/parallel.h"
#include "folder/commit.h"
#include "folder/manifest.h"
#include "g2p/folder.h"
#include "g2p/io.h"
#include "g2p/options_file.h"
#include "g2p/pipeline.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

std::string class_name(const MaterialTable& table, int label) {
  return table.valid_label(label) ? table[label].name : std::string("Unknown");
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

// segmented/image_decided.csv: the faces the segmenter decided from the image
// alone (the `regions` refiner decides only those), as inclusive ranges.
std::string image_decided_csv(const std::vector<std::uint8_t>& decided) {
  std::ostringstream out;
  out << "first_face,last_face\n";
  for (std::size_t f = 0; f < decided.size();) {
    if (decided[f] == 0) {
      ++f;
      continue;
    }
    std::size_t last = f;
    while (last + 1 < decided.size() && decided[last + 1] != 0) ++last;
    out << f << "," << last << "\n";
    f = last + 1;
  }
  return out.str();
}

// refine.json: the refine stage's record (its backend, error and notes).
std::string refine_json(const PipelineResult& r) {
  const StageReport* refine = r.stage(Stage::kRefine);
  nlohmann::json j = {{"refiner", refine != nullptr ? refine->backend : "none"}};
  if (refine != nullptr && !refine->ok) j["error"] = refine->error;
  if (refine != nullptr) j["notes"] = refine->notes;
  if (!r.refinement.labels.empty()) j["changed_faces"] = r.refinement.changes.size();
  return detail::json_text(j, 2) + "\n";
}

// The labelling stages: views, label maps, faces and parts.
Status write_labels(const std::string& tmp, const PipelineResult& r, const OutputOptions& out) {
  if (!r.views.empty()) {
    ViewFileOptions views;
    views.buffers = out.intermediates;
    G2P_RETURN_IF_ERROR(write_views(tmp + "/views", r.views, views));
  }
  if (!r.label_maps.empty()) {
    if (out.intermediates) {
      G2P_RETURN_IF_ERROR(write_label_maps(tmp + "/segmented", r.label_maps, r.table));  // with view_XX_probs.npy
    } else {
      // The class probabilities (12 floats a pixel, 138 MB for 11 views at 512 px) are intermediates.
      std::vector<LabelMap> labels_only(r.label_maps.size());
      for (std::size_t i = 0; i < r.label_maps.size(); ++i) labels_only[i].labels = r.label_maps[i].labels;
      G2P_RETURN_IF_ERROR(write_label_maps(tmp + "/segmented", labels_only, r.table));
    }
    G2P_RETURN_IF_ERROR(write_text_file(tmp + "/segmented/image_decided.csv", image_decided_csv(r.image_decided)));
  }
  if (r.last_stage < Stage::kProject) return Status::Ok();  // g2p render, g2p segment: the images only
  G2P_RETURN_IF_ERROR(write_projection(tmp, r.model, r.views, r.projection, r.table));
  return write_text_file(tmp + "/refine.json", refine_json(r));
}

// ranges.json (docs/report-schema.md#rangesjson): per part, the mass and
// contact ranges a simulation may sample for domain randomisation. The mass
// is the kind's posterior's 90 % interval where it judged the object, else
// the range of the class's densities; friction and restitution are the
// class's values widened by kContactSpread either way (libg2p's estimate:
// no surveyed table gives their spread).
std::string ranges_json(const PipelineResult& r) {
  constexpr double kContactSpread = 0.25;
  using nlohmann::json;
  const PropertiesReport& p = r.properties;
  const bool posterior = p.mass_median_kg > 0.0;
  auto spread = [](double v, double lo_limit, double hi_limit) {
    return json::array(
        {std::max(lo_limit, v * (1.0 - kContactSpread)), std::min(hi_limit, v * (1.0 + kContactSpread))});
  };
  json parts = json::array();
  for (const PartReport& part : p.parts) {
    if (!(part.mass.mass_kg > 0.0)) continue;
    const PartProperties& pp = part.properties;
    const bool judged = part.mass_median_kg > 0.0;
    parts.push_back({{"part", part.part},
                     {"material", class_name(r.table, pp.label)},
                     {"mass_kg",
                      {{"nominal", part.mass.mass_kg},
                       {"min", judged ? part.mass_p05_kg : part.mass_min_kg},
                       {"max", judged ? part.mass_p95_kg : part.mass_max_kg},
                       {"from", judged ? "posterior" : "density range"}}},
                     {"friction_static", spread(pp.friction_static, 0.0, 10.0)},
                     {"friction_dynamic", spread(pp.friction_dynamic, 0.0, 10.0)},
                     {"restitution", spread(pp.restitution, 0.0, 1.0)}});
  }
  const json object = {{"nominal", p.object.mass_kg},
                       {"min", posterior ? p.mass_p05_kg : p.mass_min_kg},
                       {"max", posterior ? p.mass_p95_kg : p.mass_max_kg},
                       {"from", posterior ? "posterior" : "density range"}};
  const json doc = {{"format", "g2p-ranges"}, {"version", 1}, {"object_mass_kg", object}, {"parts", parts}};
  return detail::json_text(doc, 2) + "\n";
}

// The simulation asset in the chosen formats.
Status write_asset_files(const std::string& tmp, const PipelineResult& r, const PipelineOptions& o) {
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
  G2P_RETURN_IF_ERROR(write_text_file(tmp + "/ranges.json", ranges_json(r)));
  return write_asset_report(tmp + "/report.json", r.properties, r.asset, r.table);
}

Status write_contents(const std::string& tmp, const PipelineResult& r, const PipelineOptions& o,
                      const OutputOptions& out) {
  const FolderManifest manifest = detail::folder_manifest(r, o, out.written_by);
  if (!manifest.materials.empty()) G2P_RETURN_IF_ERROR(r.table.save(tmp + "/" + manifest.materials));
  // Three groups of files, none writing where another does, written side by
  // side (a million-triangle run writes about 170 MB); the first failure in
  // this order is the one reported.
  const Stage last = r.last_stage;
  const std::vector<std::function<Status()>> groups = {
      [&] {
        G2P_RETURN_IF_ERROR(write_labels(tmp, r, out));
        // The corrections as face selections: the stages that start from this folder apply them.
        if (!r.overrides.empty()) return write_text_file(tmp + "/overrides.json", overrides_json(r.overrides, r.table));
        return Status::Ok();
      },
      [&] {
        // The closed volumes can be dense (grid-based): a whole run keeps them only on request.
        if (last >= Stage::kComplete && (last < Stage::kExport || out.intermediates))
          G2P_RETURN_IF_ERROR(write_completion(tmp + "/completed", r.completion, r.table, out.mesh_formats));
        if (last >= Stage::kExport) return write_asset_files(tmp, r, o);
        if (last >= Stage::kProperties) return write_report(tmp + "/report.json", r.properties, r.table);
        return Status::Ok();
      },
      [&] {
        if (out.intermediates && last >= Stage::kProject)
          G2P_RETURN_IF_ERROR(write_intermediates(tmp + "/intermediates", r));
        if (last < Stage::kExport) return Status::Ok();
        G2P_RETURN_IF_ERROR(write_text_file(tmp + "/run.json", pipeline_summary_json(r, o) + "\n"));
        G2P_RETURN_IF_ERROR(write_text_file(tmp + "/summary.html", summary_html(r, o)));
        // A whole run's options, for `g2p run --options` (a stage command's hold only its stages').
        if (r.stage(Stage::kRender) != nullptr)
          return write_text_file(tmp + "/options.json", options_file_json(RunOptions{o, r.table}));
        return Status::Ok();
      }};
  const Status written = detail::parallel_each(groups.size(), [&](std::size_t i) { return groups[i](); });
  if (!written.ok()) return written;
  // Last: a folder with a manifest is complete.
  return write_text_file(tmp + "/manifest.json", folder_manifest_json(manifest));
}

}  // namespace

Status write_pipeline_output(const std::string& dir, const PipelineResult& result, const PipelineOptions& options,
                             const OutputOptions& output) {
  if (dir.empty()) return Status::InvalidArgument("write_pipeline_output: no output folder given");
  if (result.last_stage < Stage::kRender || result.model.mesh.num_faces() == 0 ||
      (result.last_stage < Stage::kProject && result.views.empty()))
    return Status::InvalidArgument(
        "write_pipeline_output: the result holds no views (it stopped before the render stage, or failed)");
  if (result.last_stage >= Stage::kProject &&
      result.projection.labels.label.size() != static_cast<std::size_t>(result.model.mesh.num_faces()))
    return Status::InvalidArgument("write_pipeline_output: the result holds no face labels (did the run succeed?)");
  if (result.last_stage >= Stage::kExport && result.asset.parts.empty())
    return Status::InvalidArgument("write_pipeline_output: the result is incomplete (did the run succeed?)");
  OutputOptions checked = output;
  if (checked.input_path.empty() && result.model.info.path != "<memory>") checked.input_path = result.model.info.path;
  return detail::commit_folder(dir, checked, [&](const std::string& tmp, const fs::path&) {
    return write_contents(tmp, result, options, output);
  });
}

}  // namespace g2p
