// g2p validate DIR: the MJCF in MuJoCo next to libg2p's numbers, a drop onto
// a plane, and (--contact) probe balls dropped onto the object.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "g2p/export.h"
#include "g2p/io.h"
#include "json_out.h"

namespace g2p::cli {
namespace {

struct ValidateArgs {
  std::string dir;
  double height = 0.2, seconds = 2.0;
  bool contact = false, fail_on_unstable = false;
  ContactCheckOptions contact_options;
  std::vector<std::string> at;  // --at X,Y
  std::string json;
};

// `g2p validate DIR --contact`: the probe balls' table, optionally as JSON.
int run_contact_check(const ValidateArgs& args, const std::string& mjcf) {
  ContactCheckOptions options = args.contact_options;
  for (const std::string& xy : args.at) {
    double x = 0, y = 0;
    char rest = 0;
    if (std::sscanf(xy.c_str(), "%lf,%lf%c", &x, &y, &rest) != 2 || !std::isfinite(x) || !std::isfinite(y)) {
      std::cerr << "g2p validate: error: --at " << xy << ": expected X,Y in metres (the object's frame)\n";
      return kExitUsage;
    }
    options.points.emplace_back(x, y);
  }
  options.drop_height_m = args.height;
  Result<ContactCheck> c = check_contacts_in_mujoco(mjcf, options);
  if (!c.ok()) {
    std::cerr << "g2p validate: error: " << c.status().to_string() << "\n";
    return c.status().code() == StatusCode::kInvalidArgument ? kExitUsage : kExitFailure;
  }
  const Eigen::Vector3d lo = c->object_bounds.min(), hi = c->object_bounds.max();
  int resting = 0, on_object = 0;
  for (const BallProbe& b : c->balls) resting += b.at_rest ? 1 : 0, on_object += b.on_object ? 1 : 0;
  std::printf("%s: %s, object fixed, collision geometry x %.4g..%.4g y %.4g..%.4g z %.4g..%.4g m\n", mjcf.c_str(),
              c->engine.c_str(), lo.x(), hi.x(), lo.y(), hi.y(), lo.z(), hi.z());
  std::printf("  %zu balls of radius %.4g m dropped from %.4g m for %.3g s\n", c->balls.size(),
              c->balls.empty() ? 0.0 : c->balls[0].radius_m,
              hi.z() + 2 * (c->balls.empty() ? 0.0 : c->balls[0].radius_m), args.contact_options.seconds);
  std::printf("  %9s %9s %12s %12s %11s  %s\n", "start x", "start y", "rests at z", "above floor", "speed m/s",
              "where");
  for (const BallProbe& b : c->balls)
    std::printf("  %9.4f %9.4f %12.4f %12.4f %11.2e  %s%s\n", b.start.x(), b.start.y(), b.rest.z(),
                b.height_above_floor_m, b.final_speed_m_s,
                b.on_object  ? "on the object"
                : b.on_floor ? "on the floor"
                             : "touching nothing",
                b.at_rest ? "" : ", still moving");
  std::printf("  %d of %zu at rest, %d on the object\n", resting, c->balls.size(), on_object);
  if (c->drop.dropped)
    std::printf("  object dropped from %.3g m: rests %.4g m above the plane (%s)\n", args.height,
                c->drop.resting_lowest_m, c->object_above_plane ? "above it" : "sunk into it");
  else
    std::printf("  object not dropped (the MJCF fixes it to the world)\n");
  if (!args.json.empty()) {
    nlohmann::json j = {{"mjcf", mjcf}, {"engine", c->engine}, {"balls", nlohmann::json::array()}};
    j["object_bounds_m"] = {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}};
    for (const BallProbe& b : c->balls)
      j["balls"].push_back({{"start_m", {b.start.x(), b.start.y()}},
                            {"rest_m", {b.rest.x(), b.rest.y(), b.rest.z()}},
                            {"radius_m", b.radius_m},
                            {"height_above_floor_m", b.height_above_floor_m},
                            {"final_speed_m_s", b.final_speed_m_s},
                            {"at_rest", b.at_rest},
                            {"on_object", b.on_object},
                            {"on_floor", b.on_floor}});
    j["drop"] = {{"dropped", c->drop.dropped},
                 {"resting_lowest_m", c->drop.resting_lowest_m},
                 {"final_speed_m_s", c->drop.final_speed_m_s},
                 {"object_above_plane", c->object_above_plane}};
    if (Status s = write_text_file(args.json, json_out(j) + "\n"); !s.ok()) {
      std::cerr << "g2p validate: error: --json: " << s.to_string() << "\n";
      return kExitFailure;
    }
  }
  const bool stable = resting == static_cast<int>(c->balls.size()) && c->object_above_plane;
  if (!stable) std::printf("%s\n", args.fail_on_unstable ? "FAIL" : "note: not everything came to rest");
  return stable || !args.fail_on_unstable ? kExitOk : kExitFailure;
}

int run_validate(const ValidateArgs& args) {
  namespace fs = std::filesystem;
  std::string mjcf;
  std::error_code ec;
  if (!fs::is_directory(args.dir, ec)) {
    std::cerr << "g2p validate: error: " << args.dir
              << (fs::exists(args.dir, ec) ? ": not a folder (give a g2p export folder)\n" : ": no such folder\n");
    return kExitFailure;
  }
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(args.dir, ec))
    if (e.path().extension() == ".xml") found.push_back(e.path().filename().string());
  if (ec || found.empty()) {
    std::cerr << "g2p validate: error: " << args.dir << ": no MJCF (.xml) file (is this a g2p export folder?)\n";
    return kExitFailure;
  }
  if (found.size() > 1) {
    std::sort(found.begin(), found.end());
    std::string names;
    for (const std::string& f : found) names += (names.empty() ? "" : ", ") + f;
    std::cerr << "g2p validate: error: " << args.dir << ": several MJCF (.xml) files (" << names
              << "); validate reads the one g2p export wrote: move the others out\n";
    return kExitFailure;
  }
  mjcf = (fs::path(args.dir) / found.front()).string();
  if (!have_mujoco()) {
    std::cerr << "g2p validate: error: this libg2p was built without MuJoCo (G2P_WITH_MUJOCO=OFF)\n";
    return kExitFailure;
  }
  if (args.contact) return run_contact_check(args, mjcf);
  Result<EngineCheck> c = check_in_mujoco(mjcf, args.height, args.seconds);
  if (!c.ok()) {
    std::cerr << "g2p validate: error: " << c.status().to_string() << "\n";
    return kExitFailure;
  }
  // Without a free joint nothing is dropped; only the numbers are compared.
  bool pass = !c->dropped || (c->finite && c->resting_lowest_m > -0.01 && c->warnings.empty());
  std::printf("%s: %s\n", mjcf.c_str(), c->engine.c_str());
  std::printf("  %-24s %-36s %s\n", "", "engine", "libg2p (report.json)");
  std::ifstream in(args.dir + "/report.json");
  const nlohmann::json report = in ? nlohmann::json::parse(in, nullptr, false) : nlohmann::json();
  if (report.is_object() && report.contains("object")) {
    const nlohmann::json& o = report["object"];
    const double mass = o["mass_kg"].get<double>();
    std::printf("  %-24s %-36.6g %.6g\n", "mass (kg)", c->mass_kg, mass);
    char engine[96], ours[96];
    std::snprintf(engine, sizeof engine, "%.5g %.5g %.5g", c->center_of_mass.x(), c->center_of_mass.y(),
                  c->center_of_mass.z());
    std::snprintf(ours, sizeof ours, "%.5g %.5g %.5g", o["center_of_mass_m"][0].get<double>(),
                  o["center_of_mass_m"][1].get<double>(), o["center_of_mass_m"][2].get<double>());
    std::printf("  %-24s %-36s %s\n", "centre of mass (m)", engine, ours);
    std::snprintf(engine, sizeof engine, "%.5g %.5g %.5g", c->principal_moments.x(), c->principal_moments.y(),
                  c->principal_moments.z());
    std::snprintf(ours, sizeof ours, "%.5g %.5g %.5g", o["principal_moments_kg_m2"][0].get<double>(),
                  o["principal_moments_kg_m2"][1].get<double>(), o["principal_moments_kg_m2"][2].get<double>());
    std::printf("  %-24s %-36s %s\n", "principal moments", engine, ours);
    pass = pass && std::abs(c->mass_kg - mass) <= 1e-6 * mass;
    for (int a = 0; a < 3; ++a)
      pass = pass && std::abs(c->center_of_mass[a] - o["center_of_mass_m"][a].get<double>()) <= 1e-6 &&
             std::abs(c->principal_moments[a] - o["principal_moments_kg_m2"][a].get<double>()) <=
                 1e-6 * std::abs(o["principal_moments_kg_m2"][a].get<double>()) + 1e-12;
  } else {
    std::printf("  mass %.6g kg (no report.json to compare with)\n", c->mass_kg);
  }
  if (c->dropped)
    std::printf(
        "  drop from %.3g m for %.3g s: lowest point %.4g m, at rest %.4g m above the plane, final speed %.3g m/s%s\n",
        args.height, args.seconds, c->lowest_point_m, c->resting_lowest_m, c->final_speed_m_s,
        c->finite ? "" : ", NOT FINITE");
  for (const std::string& w : c->warnings) std::printf("  MuJoCo warned during the drop: %s\n", w.c_str());
  std::printf("%s\n", pass ? "PASS" : "FAIL");
  return pass ? kExitOk : kExitFailure;
}

}  // namespace

void add_validate_command(CLI::App& app, Command& run) {
  auto vargs = std::make_shared<ValidateArgs>();
  CLI::App* v = app.add_subcommand(
      "validate", "Load an exported MJCF in MuJoCo, compare, and drop it on a plane (--contact: drop balls onto it)");
  v->add_option("dir", vargs->dir, "Output folder of g2p export")->required();
  v->add_option("--drop-height", vargs->height, "Drop height above the plane, m (default 0.2)")
      ->check(finite_number(0.0, 100.0));
  v->add_option("--seconds", vargs->seconds, "Simulated time, s (default 2)")->check(finite_number(0.0, 600.0, true));
  v->add_flag("--contact", vargs->contact,
              "Contact check: fix the object, drop probe balls onto a grid over it and report where they rest");
  v->add_option("--balls", vargs->contact_options.grid,
                "--contact: balls per side of a grid over the object (default 5; 0: only --at)");
  v->add_option("--at", vargs->at, "--contact: also drop a ball over X,Y (metres, object's frame; repeatable)");
  v->add_option("--ball-radius", vargs->contact_options.ball_radius_m,
                "--contact: ball radius, m (default 2 % of the object's longest side, at least 5 mm)");
  v->add_option("--contact-seconds", vargs->contact_options.seconds, "--contact: simulated time, s (default 3)")
      ->check(finite_number(0.0, 600.0, true));
  v->add_option("--json", vargs->json, "--contact: also write the result as JSON to this file");
  v->add_flag("--fail-on-unstable", vargs->fail_on_unstable,
              "--contact: exit 1 when a ball is still moving at the end or the dropped object sank into the plane");
  v->callback([vargs, &run] { run = [vargs] { return run_validate(*vargs); }; });
}

}  // namespace g2p::cli
