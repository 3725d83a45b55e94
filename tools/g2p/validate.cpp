// g2p validate DIR: the MJCF in MuJoCo next to libg2p's numbers, a drop onto
// a plane, and (--contact) probe balls dropped onto the object.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.h"
#include "common.h"
#include "g2p/export.h"
#include "g2p/io.h"

namespace g2p::cli {
namespace {

struct ValidateArgs {
  std::string dir;
  double height = 0.2, seconds = 2.0;
  bool contact = false, fail_on_unstable = false, no_places = false;
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
  options.places = !args.no_places;
  Result<ContactCheck> c = check_contacts_in_mujoco(mjcf, options);
  if (!c.ok()) {
    const int code = fail("validate", c.status());
    return c.status().code() == StatusCode::kInvalidArgument ? kExitUsage : code;
  }
  std::cout << contact_check_text(*c, mjcf, options);
  if (!args.json.empty()) {
    if (Status s = write_text_file(args.json, contact_check_json(*c, mjcf) + "\n"); !s.ok()) {
      std::cerr << "g2p validate: error: --json: " << s.to_string() << "\n";
      return kExitFailure;
    }
  }
  const bool stable = c->stable();
  if (!stable) std::printf("%s\n", args.fail_on_unstable ? "FAIL" : "note: not everything came to rest");
  return stable || !args.fail_on_unstable ? kExitOk : kExitFailure;
}

int run_validate(const ValidateArgs& args) {
  if (!have_mujoco()) {
    std::cerr << "g2p validate: error: this libg2p was built without MuJoCo (G2P_WITH_MUJOCO=OFF)\n";
    return kExitFailure;
  }
  if (args.contact) {
    Result<std::string> mjcf = find_folder_mjcf(args.dir);
    if (!mjcf.ok()) {
      std::cerr << "g2p validate: error: " << mjcf.status().message() << "\n";
      return kExitFailure;
    }
    return run_contact_check(args, *mjcf);
  }
  Result<FolderCheck> checked = check_folder_in_mujoco(args.dir, args.height, args.seconds);
  if (!checked.ok()) {
    const Status& s = checked.status();
    const bool found = s.code() != StatusCode::kNotFound && s.code() != StatusCode::kInvalidArgument;
    std::cerr << "g2p validate: error: " << (found ? s.to_string() : s.message()) << "\n";
    return kExitFailure;
  }
  std::cout << folder_check_text(*checked);
  return checked->pass() ? kExitOk : kExitFailure;
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
              "Contact check: fix the object, drop probe balls onto a grid over it and onto its seats, table tops and "
              "cavities, and report where they rest");
  v->add_option("--balls", vargs->contact_options.grid,
                "--contact: balls per side of a grid over the object (default 5; 0: only --at and the resting places)");
  v->add_flag("--no-places", vargs->no_places,
              "--contact: drop no balls over the seats, table tops and cavities seen from above");
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
