// An export folder checked as a whole (g2p validate DIR): its one MJCF file in
// MuJoCo beside the report.json written with it, and the contact check as JSON.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/json_text.h"
#include "g2p/export.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

Eigen::Vector3d vector_of(const nlohmann::json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

// report.json's object totals; false when there is no readable report.
bool read_report(const fs::path& path, FolderCheck& c) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (!j.is_object() || !j.contains("object")) return false;
  try {
    const nlohmann::json& o = j.at("object");
    c.report_mass_kg = o.at("mass_kg").get<double>();
    c.report_center_of_mass = vector_of(o.at("center_of_mass_m"));
    c.report_principal_moments = vector_of(o.at("principal_moments_kg_m2"));
  } catch (const nlohmann::json::exception&) {
    return false;
  }
  return true;
}

}  // namespace

Result<std::string> find_folder_mjcf(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    return Status::NotFound(dir +
                            (fs::exists(dir, ec) ? ": not a folder (give a g2p export folder)" : ": no such folder"));
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".xml") found.push_back(e.path().filename().string());
  if (ec || found.empty()) return Status::NotFound(dir + ": no MJCF (.xml) file (is this a g2p export folder?)");
  if (found.size() > 1) {
    std::sort(found.begin(), found.end());
    std::string names;
    for (const std::string& f : found) names += (names.empty() ? "" : ", ") + f;
    return Status::InvalidArgument(dir + ": several MJCF (.xml) files (" + names +
                                   "); validate reads the one g2p export wrote: move the others out");
  }
  return (fs::path(dir) / found.front()).string();
}

Result<FolderCheck> check_folder_in_mujoco(const std::string& dir, double drop_height_m, double drop_seconds) {
  Result<std::string> mjcf = find_folder_mjcf(dir);
  if (!mjcf.ok()) return mjcf.status();
  FolderCheck c;
  c.mjcf = *mjcf;
  c.drop_height_m = drop_height_m;
  c.drop_seconds = drop_seconds;
  Result<EngineCheck> engine = check_in_mujoco(c.mjcf, drop_height_m, drop_seconds);
  if (!engine.ok()) return engine.status();
  c.engine = std::move(*engine);
  // Without a free joint nothing is dropped; only the numbers are compared.
  c.drop_ok = !c.engine.dropped || (c.engine.finite && c.engine.resting_lowest_m > -0.01 && c.engine.warnings.empty());
  c.has_report = read_report(fs::path(dir) / "report.json", c);
  if (c.has_report) {
    const double mass = c.report_mass_kg;
    c.numbers_match = std::abs(c.engine.mass_kg - mass) <= 1e-6 * mass;
    for (int a = 0; a < 3; ++a)
      c.numbers_match = c.numbers_match && std::abs(c.engine.center_of_mass[a] - c.report_center_of_mass[a]) <= 1e-6 &&
                        std::abs(c.engine.principal_moments[a] - c.report_principal_moments[a]) <=
                            1e-6 * std::abs(c.report_principal_moments[a]) + 1e-12;
  }
  return c;
}

std::string contact_check_json(const ContactCheck& c, const std::string& mjcf) {
  const Eigen::Vector3d lo = c.object_bounds.min(), hi = c.object_bounds.max();
  nlohmann::json j = {{"mjcf", mjcf}, {"engine", c.engine}, {"balls", nlohmann::json::array()}};
  j["object_bounds_m"] = {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}};
  for (const BallProbe& b : c.balls)
    j["balls"].push_back({{"start_m", {b.start.x(), b.start.y()}},
                          {"rest_m", {b.rest.x(), b.rest.y(), b.rest.z()}},
                          {"radius_m", b.radius_m},
                          {"height_above_floor_m", b.height_above_floor_m},
                          {"final_speed_m_s", b.final_speed_m_s},
                          {"at_rest", b.at_rest},
                          {"on_object", b.on_object},
                          {"on_floor", b.on_floor},
                          {"place", b.place < 0 ? nlohmann::json(nullptr) : nlohmann::json(b.place)},
                          {"rests_in", b.rests_in < 0 ? nlohmann::json(nullptr) : nlohmann::json(b.rests_in)}});
  j["places"] = nlohmann::json::array();
  for (const PlaceProbe& p : c.places) {
    nlohmann::json probes = nlohmann::json::array();
    for (const Eigen::Vector2d& at : p.place.probes) probes.push_back({at.x(), at.y()});
    j["places"].push_back({{"name", p.place.name},
                           {"kind", resting_place_kind_name(p.place.kind)},
                           {"z_m", p.place.z_m},
                           {"area_m2", p.place.area_m2},
                           {"depth_m", p.place.depth_m},
                           {"slope_deg", p.place.slope_deg},
                           {"inner_radius_m", p.place.inner_radius_m},
                           {"probes_m", probes},
                           {"dropped", p.dropped},
                           {"stayed", p.stayed}});
  }
  j["drop"] = {{"dropped", c.drop.dropped},
               {"resting_lowest_m", c.drop.resting_lowest_m},
               {"final_speed_m_s", c.drop.final_speed_m_s},
               {"object_above_plane", c.object_above_plane}};
  return detail::json_text(j, 2);
}

std::string folder_check_text(const FolderCheck& f) {
  const EngineCheck& c = f.engine;
  auto triple = [](const Eigen::Vector3d& v) {
    char text[96];
    std::snprintf(text, sizeof text, "%.5g %.5g %.5g", v.x(), v.y(), v.z());
    return std::string(text);
  };
  std::string out;
  char line[512];
  auto add = [&](int n) {
    out.append(line, static_cast<std::size_t>(std::clamp(n, 0, static_cast<int>(sizeof line) - 1)));
  };
  add(std::snprintf(line, sizeof line, "%s: %s\n  %-24s %-36s %s\n", f.mjcf.c_str(), c.engine.c_str(), "", "engine",
                    "libg2p (report.json)"));
  if (f.has_report) {
    add(std::snprintf(line, sizeof line, "  %-24s %-36.6g %.6g\n", "mass (kg)", c.mass_kg, f.report_mass_kg));
    add(std::snprintf(line, sizeof line, "  %-24s %-36s %s\n", "centre of mass (m)", triple(c.center_of_mass).c_str(),
                      triple(f.report_center_of_mass).c_str()));
    add(std::snprintf(line, sizeof line, "  %-24s %-36s %s\n", "principal moments", triple(c.principal_moments).c_str(),
                      triple(f.report_principal_moments).c_str()));
  } else {
    add(std::snprintf(line, sizeof line, "  mass %.6g kg (no report.json to compare with)\n", c.mass_kg));
  }
  if (c.dropped) {
    // At rest: slower than the probe balls' limit (ContactCheckOptions::
    // rest_speed_m_s). A body still moving at the end (a hammer toppling) is
    // reported as moving, with the flag that gives it time to settle.
    const bool at_rest = c.finite && c.final_speed_m_s < ContactCheckOptions().rest_speed_m_s;
    add(std::snprintf(line, sizeof line,
                      "  drop from %.3g m for %.3g s: lowest point %.4g m, at the end %.4g m above the plane, %s "
                      "(%.3g m/s)%s\n",
                      f.drop_height_m, f.drop_seconds, c.lowest_point_m, c.resting_lowest_m,
                      at_rest ? "at rest" : "still moving", c.final_speed_m_s,
                      !c.finite ? ", NOT FINITE"
                      : at_rest ? ""
                                : "; --seconds longer lets it settle"));
  }
  for (const std::string& w : c.warnings) out += "  MuJoCo warned during the drop: " + w + "\n";
  return out + (f.pass() ? "PASS\n" : "FAIL\n");
}

std::string contact_check_text(const ContactCheck& c, const std::string& mjcf, const ContactCheckOptions& options) {
  const Eigen::Vector3d lo = c.object_bounds.min(), hi = c.object_bounds.max();
  const double radius = c.balls.empty() ? 0.0 : c.balls[0].radius_m;
  int resting = 0, on_object = 0;
  for (const BallProbe& b : c.balls) resting += b.at_rest ? 1 : 0, on_object += b.on_object ? 1 : 0;
  std::string out;
  char line[512];
  auto add = [&](int n) {
    out.append(line, static_cast<std::size_t>(std::clamp(n, 0, static_cast<int>(sizeof line) - 1)));
  };
  add(std::snprintf(line, sizeof line,
                    "%s: %s, object fixed, collision geometry x %.4g..%.4g y %.4g..%.4g z %.4g..%.4g m\n", mjcf.c_str(),
                    c.engine.c_str(), lo.x(), hi.x(), lo.y(), hi.y(), lo.z(), hi.z()));
  add(std::snprintf(line, sizeof line, "  %zu balls of radius %.4g m dropped from %.4g m for %.3g s\n", c.balls.size(),
                    radius, hi.z() + 2 * radius, options.seconds));
  add(std::snprintf(line, sizeof line, "  %9s %9s %12s %12s %11s  %s\n", "start x", "start y", "rests at z",
                    "above floor", "speed m/s", "where"));
  for (const BallProbe& b : c.balls) {
    std::string where = b.on_object ? "on the object" : b.on_floor ? "on the floor" : "touching nothing";
    if (b.rests_in >= 0 && b.rests_in < static_cast<int>(c.places.size())) {
      const RestingPlace& r = c.places[static_cast<std::size_t>(b.rests_in)].place;
      where = (r.kind == RestingPlaceKind::kCavity ? "in " : "on ") + r.name;
    }
    if (b.place >= 0 && b.place < static_cast<int>(c.places.size()))
      where += " (dropped over " + c.places[static_cast<std::size_t>(b.place)].place.name + ")";
    add(std::snprintf(line, sizeof line, "  %9.4f %9.4f %12.4f %12.4f %11.2e  %s%s\n", b.start.x(), b.start.y(),
                      b.rest.z(), b.height_above_floor_m, b.final_speed_m_s, where.c_str(),
                      b.at_rest ? "" : ", still moving"));
  }
  add(std::snprintf(line, sizeof line, "  %d of %zu at rest, %d on the object\n", resting, c.balls.size(), on_object));
  for (const PlaceProbe& p : c.places) {
    const RestingPlace& r = p.place;
    if (r.kind == RestingPlaceKind::kCavity)
      add(std::snprintf(line, sizeof line,
                        "  %s (bottom at z %.3g m, %.3g m deep, %.3g m^2): %d of %d balls at rest inside it\n",
                        r.name.c_str(), r.rim_z_m - r.depth_m, r.depth_m, r.area_m2, p.stayed, p.dropped));
    else
      add(std::snprintf(line, sizeof line,
                        "  %s (at z %.3g m, %.3g m^2, sloping %.0f degrees): %d of %d balls at rest on it\n",
                        r.name.c_str(), r.z_m, r.area_m2, r.slope_deg, p.stayed, p.dropped));
  }
  if (c.places.empty() && options.places) out += "  no seat, table top or cavity seen from above\n";
  if (c.drop.dropped)
    add(std::snprintf(line, sizeof line, "  object dropped from %.3g m: rests %.4g m above the plane (%s)\n",
                      options.drop_height_m, c.drop.resting_lowest_m,
                      c.object_above_plane ? "above it" : "sunk into it"));
  else
    out += "  object not dropped (the MJCF fixes it to the world)\n";
  return out;
}

}  // namespace g2p
