// --overrides FILE on the commands that start from a labelled object (g2p
// refine, complete, properties, export): a person's corrections
// (g2p/overrides.h, docs/pipeline.md#overrides). A folder made with
// corrections keeps them in its overrides.json, as face selections, and every
// command that starts from the folder applies them again first.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "g2p/overrides.h"
#include "g2p/project.h"

namespace g2p::cli {

void add_overrides_flag(CLI::App* cmd, std::string& path);

// The corrections one command applied, file after file.
struct AppliedOverrides {
  Overrides combined;                           // every file's, as face selections, in order
  std::shared_ptr<ResolvedOverrides> resolved;  // `combined` on the final labels (finish_overrides)
  std::vector<std::string> notes;               // what each file changed
  bool changed_classes = false;                 // some face took another class

  bool empty() const { return combined.empty(); }
  bool changes_properties() const { return combined.changes_properties(); }
};

// Reads `path`, checks it against the object's current parts and labels and
// gives the selected faces their classes (the parts re-form). A bad file or
// one made for another run prints the error and sets exit_code to the usage
// code; nothing else changes then. `carried`: the file is a folder's own
// overrides.json, not --overrides (errors say so).
Status apply_overrides_file(const std::string& command, const std::string& path, const Mesh& mesh,
                            const MaterialTable& table, FacesFile& faces, AppliedOverrides& applied, int& exit_code,
                            bool carried = false);
Status apply_overrides_file(const std::string& command, const std::string& path, const Mesh& mesh,
                            const MaterialTable& table, Projection& projection, AppliedOverrides& applied,
                            int& exit_code, bool carried = false);

// Resolves the combined corrections on the final labels (for the estimator).
void finish_overrides(int num_faces, const std::vector<Part>& parts, const std::vector<int>& labels,
                      const MaterialTable& table, AppliedOverrides& applied);

// DIR/overrides.json when there are corrections; removes an old one otherwise.
Status write_overrides(const std::string& dir, const AppliedOverrides& applied, const MaterialTable& table);

}  // namespace g2p::cli
