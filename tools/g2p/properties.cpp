// g2p properties SOURCE -o OUT: stages 5 and 6, every part closed and given
// its density, structure and mass properties; writes report.json and the
// closed part meshes (OUT/completed). SOURCE as for `g2p complete`.
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "g2p/properties.h"
#include "stage_inputs.h"

namespace g2p::cli {
namespace {

struct PropertiesArgs {
  LabelledSourceArgs source;
  CompleterArgs completer;
  std::string out;
  EstimatorArgs estimator;
};

// The plausible mass range of labels.json's entry, if it has one.
bool plausible_range(const std::string& truth, const std::string& key, double& lo, double& hi) {
  std::ifstream in(truth);
  if (!in) return false;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) return false;
  const nlohmann::json* entry = j.contains("models") && j["models"].contains(key) ? &j["models"][key] : &j;
  if (!entry->contains("real_mass_kg") || !(*entry)["real_mass_kg"].is_array() || (*entry)["real_mass_kg"].size() != 2)
    return false;
  lo = (*entry)["real_mass_kg"][0].get<double>();
  hi = (*entry)["real_mass_kg"][1].get<double>();
  return true;
}

int run_properties(const PropertiesArgs& args) {
  int exit_code = kExitOk;
  const bool folder = std::filesystem::is_directory(args.source.source);
  if (!folder && args.out.empty()) {
    std::cerr << "g2p properties: error: give -o OUT for a model file\n";
    return kExitUsage;
  }
  {  // Bad estimator flags fail before any work.
    Result<BackendSettings> settings = parse_settings(args.estimator.settings);
    if (!settings.ok() || !make_estimator(args.estimator.name, *settings).ok()) {
      std::cerr << "g2p properties: error: "
                << (settings.ok() ? make_estimator(args.estimator.name, *settings).status().to_string()
                                  : settings.status().to_string())
                << "\n";
      return kExitUsage;
    }
  }
  Result<LabelledObject> object = load_labelled_source("properties", args.source, exit_code);
  if (!object.ok()) return exit_code;
  Result<Completion> done = run_completion("properties", args.completer, *object, exit_code);
  if (!done.ok()) return exit_code;
  Result<PropertiesReport> report = run_estimation("properties", args.estimator, *object, *done, exit_code);
  if (!report.ok()) return exit_code;
  const std::string out = args.out.empty() ? args.source.source + "/properties" : args.out;
  Status s = write_completion(out + "/completed", *done, object->table);
  if (s.ok()) s = write_report(out + "/report.json", *report, object->table);
  if (s.ok()) s = write_properties_manifest(out, args.source);
  if (s.ok()) s = write_overrides(out, object->overrides, object->table);
  if (!s.ok()) {
    std::cerr << "g2p properties: error: " << s.to_string() << "\n";
    return kExitFailure;
  }
  std::cout << std::setprecision(4);
  for (const PartReport& r : report->parts) {
    const PartProperties& p = r.properties;
    std::cout << "  part " << r.part << " " << object->table[p.label].name << ": " << to_string(p.structure);
    if (p.structure == Structure::kHollow) std::cout << " (" << p.wall_thickness_m * 1000 << " mm walls)";
    std::cout << ", " << p.density_kg_m3 << " kg/m^3 (" << to_string(p.density_source) << "), " << r.mass.mass_kg
              << " kg\n";
  }
  const MassProperties& m = report->object;
  std::cout << "object: " << m.mass_kg << " kg (range " << report->mass_min_kg << " - " << report->mass_max_kg
            << "), centre of mass " << m.center_of_mass.transpose() << " m -> " << out << "/report.json\n";
  for (const std::string& n : report->notes) std::cout << "  note: " << n << "\n";
  double lo = 0, hi = 0;
  const std::string key =
      args.source.key.empty() ? std::filesystem::path(args.source.source).stem().string() : args.source.key;
  if (!args.source.truth.empty() && plausible_range(args.source.truth, key, lo, hi))
    std::cout << "plausible mass " << lo << " - " << hi << " kg (" << args.source.truth
              << "): " << (m.mass_kg >= lo && m.mass_kg <= hi ? "inside" : "OUTSIDE") << "\n";
  return kExitOk;
}

}  // namespace

void add_properties_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<PropertiesArgs>();
  CLI::App* cmd = app.add_subcommand(
      "properties", "Close every part and estimate density, structure and mass properties (stages 5 and 6)");
  add_labelled_source_flags(cmd, args->source);
  cmd->add_option("-o,--output", args->out, "Output folder (default SOURCE/properties for a folder)");
  add_estimator_flags(cmd, args->estimator);
  add_completer_flags(cmd, args->completer);
  cmd->callback([args, &run] { run = [args] { return run_properties(*args); }; });
}

}  // namespace g2p::cli
