// estimate_properties (the whole stage) and report.json (docs/report-schema.md).
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/json_text.h"
#include "core/physical_limits.h"
#include "g2p/io.h"
#include "g2p/properties.h"
#include "properties/report.h"

namespace g2p {

namespace {

// Fills a hollow part's cavity (its closed volume less its walls) as its
// contents ask, or says why not; the part's mass then holds both.
void add_contents(PartReport& r, const Mesh& closed, bool closed_ok, std::vector<std::string>& report_notes) {
  PartProperties& pp = r.properties;
  auto skip = [&](const std::string& why) {
    pp.notes.push_back(kContentsLeftOut + why);
    report_notes.push_back("part " + std::to_string(r.part) + ": " + kContentsLeftOut + why);
  };
  std::ostringstream bad;
  if (!(pp.contents_fill >= 0.0 && pp.contents_fill <= 1.0)) {
    bad << "the fill " << pp.contents_fill << " is not a share of the cavity from 0 to 1 (80 % is 0.8)";
    return skip(bad.str());
  }
  if (!(pp.contents_density_kg_m3 > 0.0 && pp.contents_density_kg_m3 <= detail::kMaxDensity_kg_m3)) {
    bad << "the fill's density " << pp.contents_density_kg_m3 << " kg/m^3 is not between 0 and "
        << detail::kMaxDensity_kg_m3;
    return skip(bad.str());
  }
  if (pp.structure != Structure::kHollow)
    return skip("the part is solid and has no cavity (make it hollow to fill it: \"structure\": \"hollow\")");
  if (!closed_ok) return skip("its closed volume failed the complete stage's checks, so its cavity is not known");
  Result<MassProperties> whole = solid_mass_properties(closed, 1.0);
  if (!whole.ok()) return skip(whole.status().message());
  const double cavity = whole->volume_m3 - r.mass.volume_m3;
  if (!(cavity > 0.0)) return skip("its walls fill its closed volume");
  Result<MassProperties> fill = fill_mass_properties(closed, pp.contents_density_kg_m3, pp.contents_fill * cavity);
  if (!fill.ok()) return skip(fill.status().message());
  r.contents = *fill;
  r.mass = combine({r.mass, *fill});
  r.mass_min_kg += fill->mass_kg;
  r.mass_max_kg += fill->mass_kg;
  std::ostringstream note;
  note << "contents: " << 100.0 * pp.contents_fill << " % of a " << cavity * 1000.0 << " l cavity at "
       << pp.contents_density_kg_m3 << " kg/m^3, " << fill->mass_kg << " kg";
  pp.notes.push_back(note.str());
}

}  // namespace

Result<PropertiesReport> estimate_properties(const Mesh& object, const std::vector<Part>& parts,
                                             const Completion& completion, const MaterialTable& table,
                                             const PropertyEstimator& estimator, const std::vector<View>* views,
                                             const StageProgress& progress) {
  if (completion.parts.size() != parts.size())
    return Status::InvalidArgument("properties: " + std::to_string(completion.parts.size()) + " completed parts for " +
                                   std::to_string(parts.size()) + " parts");
  // One ray structure of the object for every part's wall measurement.
  Result<std::shared_ptr<const SurfaceRays>> object_rays = SurfaceRays::build(object);
  if (!object_rays.ok()) return object_rays.status().with_context("properties");
  return detail::estimate_properties(object, parts, completion, table, estimator, views, progress, **object_rays);
}

Result<PropertiesReport> detail::estimate_properties(const Mesh& object, const std::vector<Part>& parts,
                                                     const Completion& completion, const MaterialTable& table,
                                                     const PropertyEstimator& estimator, const std::vector<View>* views,
                                                     const StageProgress& progress, const SurfaceRays& object_rays) {
  if (completion.parts.size() != parts.size())
    return Status::InvalidArgument("properties: " + std::to_string(completion.parts.size()) + " completed parts for " +
                                   std::to_string(parts.size()) + " parts");
  PropertiesReport report;
  std::vector<MassProperties> masses;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (progress && i > 0)
      G2P_RETURN_IF_ERROR(progress(static_cast<double>(i) / static_cast<double>(parts.size()),
                                   "part " + std::to_string(i - 1) + " weighed"));
    const CompletedPart& completed = completion.parts[i];
    PartReport r;
    r.part = static_cast<int>(i);
    r.completed_ok = completed.ok;
    PropertyInput in{&object, &parts[i], &completed, &table, views, &parts, &completion, &object_rays};
    Result<PartProperties> p = estimator.estimate(in);
    if (!p.ok()) return p.status().with_context("part " + std::to_string(i));
    r.properties = std::move(*p);
    if (completed.mesh.num_faces() == 0) {
      r.properties.notes.push_back("no closed volume: left out of the object's totals");
      report.notes.push_back("part " + std::to_string(i) + " has no closed volume and is left out");
      report.parts.push_back(std::move(r));
      continue;
    }
    const PartProperties& pp = r.properties;
    Result<MassProperties> m =
        pp.structure == Structure::kHollow
            ? shell_mass_properties(part_patch(object, parts[i]), pp.density_kg_m3,
                                    pp.double_walled ? 0.5 * pp.wall_thickness_m : pp.wall_thickness_m)
            : solid_mass_properties(completed.mesh, pp.density_kg_m3);
    if (!m.ok()) {
      r.properties.notes.push_back("mass properties failed: " + m.status().message());
      report.notes.push_back("part " + std::to_string(i) + ": " + m.status().message() + "; left out");
      report.parts.push_back(std::move(r));
      continue;
    }
    r.mass = *m;
    r.mass_min_kg = m->mass_kg * pp.density_min_kg_m3 / pp.density_kg_m3;
    r.mass_max_kg = m->mass_kg * pp.density_max_kg_m3 / pp.density_kg_m3;
    if (pp.contents_fill != 0.0) add_contents(r, completed.mesh, completed.ok, report.notes);
    if (!completed.ok) {
      std::string why;  // the volume check's verdict, the one a user acts on
      for (const std::string& n : completed.notes)
        if (n.rfind("volume check: ", 0) == 0) why = " (" + n + ")";
      report.notes.push_back("part " + std::to_string(i) + " failed its completion checks" + why);
    }
    masses.push_back(r.mass);
    report.mass_min_kg += r.mass_min_kg;
    report.mass_max_kg += r.mass_max_kg;
    report.parts.push_back(std::move(r));
  }
  if (masses.empty()) return Status::InvalidArgument("properties: no part has a closed volume");
  report.object = combine(masses);
  if (!object.positions.empty()) report.size.extent_m = bounds(object).sizes();
  return report;
}

namespace {

using nlohmann::json;

json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }
json mat(const Eigen::Matrix3d& m) {
  json rows = json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(json::array({m(r, 0), m(r, 1), m(r, 2)}));
  return rows;
}

// The kind's mass posterior's median and 90 % interval, or null where it did not judge.
json interval_json(double median, double p05, double p95) {
  if (!(median > 0.0)) return nullptr;
  return {{"median", median}, {"p05", p05}, {"p95", p95}};
}

json mass_json(const MassProperties& m) {
  return {{"mass_kg", m.mass_kg},
          {"center_of_mass_m", vec(m.center_of_mass)},
          {"inertia_kg_m2", mat(m.inertia)},
          {"principal_moments_kg_m2", vec(m.principal_moments())},
          {"principal_axes", mat(m.principal_axes())}};
}

}  // namespace

std::string report_json(const PropertiesReport& report, const MaterialTable& table) {
  json parts = json::array();
  for (const PartReport& r : report.parts) {
    const PartProperties& p = r.properties;
    json j = mass_json(r.mass);
    j["part"] = r.part;
    j["material"] = table.valid_label(p.label) ? table[p.label].name : std::string("Unknown");
    j["structure"] = to_string(p.structure);
    j["density_kg_m3"] = p.density_kg_m3;
    j["density_min_kg_m3"] = p.density_min_kg_m3;
    j["density_max_kg_m3"] = p.density_max_kg_m3;
    j["wall_thickness_m"] = p.structure == Structure::kHollow ? json(p.wall_thickness_m) : json(nullptr);
    j["double_walled"] = p.double_walled;
    j["material_volume_m3"] = r.mass.volume_m3 - r.contents.volume_m3;
    if (r.contents.mass_kg > 0.0)
      j["contents"] = {{"density_kg_m3", p.contents_density_kg_m3},
                       {"fill", p.contents_fill},
                       {"volume_m3", r.contents.volume_m3},
                       {"mass_kg", r.contents.mass_kg},
                       {"center_of_mass_m", vec(r.contents.center_of_mass)}};
    else
      j["contents"] = nullptr;
    j["area_m2"] = r.mass.area_m2;
    j["mass_min_kg"] = r.mass_min_kg;
    j["mass_max_kg"] = r.mass_max_kg;
    j["mass_interval_kg"] = interval_json(r.mass_median_kg, r.mass_p05_kg, r.mass_p95_kg);
    j["friction_static"] = p.friction_static;
    j["friction_dynamic"] = p.friction_dynamic;
    j["restitution"] = p.restitution;
    j["mujoco_solref"] = p.solref;
    j["mujoco_solimp"] = p.solimp;
    j["sources"] = {{"density", to_string(p.density_source)},
                    {"structure", to_string(p.structure_source)},
                    {"wall_thickness", to_string(p.thickness_source)},
                    {"contact", to_string(p.contact_source)}};
    j["walls"] = {{"rays", p.walls.rays},
                  {"inner_fraction", p.walls.inner_fraction()},
                  {"median_thickness_m", p.walls.thickness_m},
                  {"median_inner_wall_m", p.walls.inner_wall_m}};
    j["completion_ok"] = r.completed_ok;
    j["notes"] = p.notes;
    parts.push_back(j);
  }
  json object = mass_json(report.object);
  object["mass_min_kg"] = report.mass_min_kg;
  object["mass_max_kg"] = report.mass_max_kg;
  object["mass_interval_kg"] = interval_json(report.mass_median_kg, report.mass_p05_kg, report.mass_p95_kg);
  object["mass_judged_by"] = report.mass_judged_by.empty() ? json(nullptr) : json(report.mass_judged_by);
  object["kind_mass_range_kg"] =
      report.kind_range_kg[1] > 0.0 ? json::array({report.kind_range_kg[0], report.kind_range_kg[1]}) : json(nullptr);
  double contents_volume = 0.0;
  for (const PartReport& r : report.parts) contents_volume += r.contents.volume_m3;
  object["material_volume_m3"] = report.object.volume_m3 - contents_volume;
  object["area_m2"] = report.object.area_m2;
  const ObjectSize& size = report.size;
  object["size"] = {
      {"extent_m", vec(size.extent_m)},
      {"height_m", size.extent_m.z()},
      {"longest_side_m", size.extent_m.maxCoeff()},
      {"scale_source", size.scale_source.empty() ? json(nullptr) : json(size.scale_source)},
      {"metres_per_file_unit", size.metres_per_file_unit > 0 ? json(size.metres_per_file_unit) : json(nullptr)},
      {"looks_normalised", size.looks_normalised}};
  json doc = {{"format", "g2p.properties"}, {"version", 1},   {"material_table", table.name()},
              {"object", object},           {"parts", parts}, {"notes", report.notes}};
  return detail::json_text(doc, 2) + "\n";
}

Status write_report(const std::string& path, const PropertiesReport& report, const MaterialTable& table) {
  return write_text_file(path, report_json(report, table));
}

}  // namespace g2p
