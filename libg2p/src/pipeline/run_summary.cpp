// run.json: the machine-readable summary of a run (pipeline_summary_json),
// and what it and summary.html say about each part.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/json_text.h"
#include "g2p/pipeline.h"
#include "pipeline/run_summary.h"

namespace g2p {
namespace {

nlohmann::json vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::string class_name(const MaterialTable& table, int label) {
  return table.valid_label(label) ? table[label].name : std::string("Unknown");
}

}  // namespace

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

std::string pipeline_summary_text(const PipelineResult& r) {
  std::string out;
  char line[512];
  const Identification& id = r.identification;
  if (r.stage(Stage::kIdentify) != nullptr) {
    if (id.known())
      std::snprintf(line, sizeof line, "object: %s (%s, %.0f %% confident)%s\n", id.kind().c_str(), id.source().c_str(),
                    100.0 * id.confidence(),
                    r.kind.name.empty()    ? ", below --kind-confidence: nothing assumed from it"
                    : r.size_assumed_m > 0 ? ", its typical size assumed"
                                           : "");
    else
      std::snprintf(line, sizeof line, "object: unknown (give it with --object)\n");
    out += line;
  }
  for (const StageReport& s : r.stages) {
    std::snprintf(line, sizeof line, "  %-10s %-10s %6.2f s %7.0f MiB%s\n", to_string(s.stage), s.backend.c_str(),
                  s.seconds, static_cast<double>(s.peak_rss_bytes) / 1048576.0, s.ok ? "" : "  FAILED (skipped)");
    out += line;
  }
  for (std::size_t i = 0; i < r.projection.parts.size(); ++i) {
    const Part& p = r.projection.parts[i];
    std::snprintf(line, sizeof line, "  part %zu: %s, %zu faces, %.6g m^2", i,
                  r.table.valid_label(p.label) ? r.table[p.label].name.c_str() : "(unknown)", p.faces.size(),
                  p.area_m2);
    out += line;
    if (i < r.completion.parts.size()) {
      std::snprintf(line, sizeof line, ", %s %.6g cm^3", r.completion.parts[i].ok ? "closed" : "NOT CLOSED",
                    r.completion.parts[i].checks.volume_m3 * 1e6);
      out += line;
    }
    if (i < r.properties.parts.size()) {
      const PartReport& pr = r.properties.parts[i];
      std::snprintf(line, sizeof line, ", %s, %.4g kg/m^3 (%s), %.4g kg", to_string(pr.properties.structure),
                    pr.properties.density_kg_m3, to_string(pr.properties.density_source), pr.mass.mass_kg);
      out += line;
    }
    out += "\n";
  }
  if (r.last_stage >= Stage::kProperties && !r.properties.parts.empty()) {
    const Eigen::Vector3d& c = r.properties.object.center_of_mass;
    std::snprintf(line, sizeof line, "mass: %.4g kg (range %.3g - %.3g), centre of mass (%.4g %.4g %.4g) m\n",
                  r.properties.object.mass_kg, r.properties.mass_min_kg, r.properties.mass_max_kg, c.x(), c.y(), c.z());
    out += line;
    if (r.properties.mass_median_kg > 0.0) {
      std::snprintf(line, sizeof line, "  %s: median %.3g kg, 90 %% interval %.3g - %.3g kg (",
                    r.properties.kind_range_kg[1] > 0.0 ? "with its kind" : "as everyday objects weigh",
                    r.properties.mass_median_kg, r.properties.mass_p05_kg, r.properties.mass_p95_kg);
      out += line + r.properties.mass_judged_by + ")\n";
    }
  }
  return out;
}

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
    // At the object's size where the kind's mass posterior scaled the range (PropertiesReport::kind_range_kg).
    const bool scaled = r.properties.kind_range_kg[1] > 0.0;
    const double lo = scaled ? r.properties.kind_range_kg[0] : r.kind.mass_kg[0];
    const double hi = scaled ? r.properties.kind_range_kg[1] : r.kind.mass_kg[1];
    identification["mass_in_kind_range"] =
        known ? nlohmann::json(m.mass_kg >= lo && m.mass_kg <= hi) : nlohmann::json(nullptr);
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
