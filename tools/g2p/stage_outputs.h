// The project and refine stages' shared steps: applying a refiner to a
// projection and writing the labelled results. Used by `g2p project` and
// `g2p refine`.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "g2p/project.h"
#include "g2p/refine.h"

namespace g2p::cli {

// --refiner NAME and --refine-set KEY=VALUE.
struct RefineArgs {
  std::string name = "none";
  std::vector<std::string> settings;
};
void add_refiner_flags(CLI::App* cmd, RefineArgs& args, const std::string& default_name);

// The refiner the flags name, or null for "none"; prints a usage error and
// sets exit_code to kExitUsage when they are bad.
Result<std::unique_ptr<Refiner>> make_refiner_flag(const std::string& command, const RefineArgs& args, int& exit_code);

// Runs `refiner` (null: nothing) on the projection and re-partitions with its
// labels; `report` gets what refine_projection writes to refine.json. A
// refiner failure keeps the projected labels (a warning; the report says
// why). With print_notes, its notes go to stdout. `image_decided` is the
// segmenter's Segmenter::image_decided_faces() (null: not known).
int apply_refiner(const std::string& command, const std::string& name, const Refiner* refiner, const Model& model,
                  const std::vector<View>& views, const MaterialTable& table, const PartitionOptions& partition,
                  Projection& projection, nlohmann::json& report, bool print_notes,
                  const std::vector<std::uint8_t>* image_decided = nullptr,
                  const std::vector<float>* class_prior = nullptr);

// Runs the refiner on the projection and re-partitions with its labels. A
// refiner failure keeps the projected labels (a warning; the report says
// why). Returns an exit code: kExitOk, or kExitUsage for bad flags.
int refine_projection(const std::string& command, const RefineArgs& args, const Model& model,
                      const std::vector<View>& views, const MaterialTable& table, const PartitionOptions& partition,
                      Projection& projection, nlohmann::json& report,
                      const std::vector<std::uint8_t>* image_decided = nullptr);

// faces.csv, labelled.ply, parts.json, refine.json and projected/ label maps.
Status write_projection(const std::string& out, const Model& model, const std::vector<View>& views,
                        const Projection& projection, const MaterialTable& table, const nlohmann::json& report);

// One line per part on stdout.
void print_parts(const Projection& projection, const MaterialTable& table);

}  // namespace g2p::cli
