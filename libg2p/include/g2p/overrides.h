// overrides: corrections a person makes to a run's result, applied by later
// runs. summary.html writes them (pick a part, choose another class, solid or
// hollow, a wall thickness or a density, download overrides.json); `g2p run`,
// `g2p refine`, `g2p properties` and `g2p export` take them with --overrides,
// and the stages after the change run again. The file format is versioned and
// documented in docs/pipeline.md#overrides.
//
//   {"format": "g2p-overrides", "version": 1, "model": "chair.glb", "faces_total": 12000,
//    "overrides": [{"part": 2, "was": {"class": "Fabric", "faces": 4100}, "class": "Leather"},
//                  {"faces": [17, [40, 95]], "class": "Metal", "density_kg_m3": 7850}]}
//
// An entry selects faces (a part of the run the file was made from, or face
// indices of the input: the rows of faces.csv) and sets any of class,
// structure, wall thickness, density and contents (a fill of a hollow part's
// cavity: {"part": 0, "contents": {"fill": 0.8, "density_kg_m3": 1000}}). Classes change before the complete
// stage (the parts are re-formed from the new labels); the other values
// replace the estimator's for the parts that hold the selected faces. A
// top-level "object": "chair" corrects what the object is (identify.h): the
// run takes it as the user's words, as `--object` would be.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/project.h"
#include "g2p/properties.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

constexpr int kOverridesVersion = 1;  // the "version" this libg2p writes and reads

// One correction.
struct Override {
  // Which faces (exactly one of the two):
  int part = -1;                          // >= 0: every face of this part of the run the file was made from
  std::vector<std::array<int, 2>> faces;  // inclusive ranges of input face indices (faces.csv rows)
  // Optional checks that the part is the one the person saw ("was"): applying
  // a file to another model or run fails instead of changing the wrong faces.
  std::string was_class;  // "" = not checked
  int was_faces = -1;     // -1 = not checked
  // New values; what is left unset keeps what the stages decide.
  int label = kUnknownLabel;                // the new class (an index of the table), kUnknownLabel = keep
  std::string class_name;                   // its name as the file gives it (resolve_overrides looks it up again)
  bool set_structure = false;               // true: `structure` applies
  Structure structure = Structure::kSolid;  // solid or hollow
  double wall_thickness_m = 0.0;            // > 0: the wall (implies hollow), metres
  double density_kg_m3 = 0.0;               // > 0: the density, kg/m^3 (its plausible range becomes this value)
  // Contents ("contents": {"fill": 0.5, "density_kg_m3": 1000}): the share of
  // a hollow part's cavity that a fill of this density takes (0 = empty).
  bool set_contents = false;               // true: the two below apply
  double contents_fill = 0.0;              // 0 to 1
  double contents_density_kg_m3 = 1000.0;  // kg/m^3, water unless given
  std::string note;                        // the person's words, kept in the reports

  bool sets_structure() const { return set_structure || wall_thickness_m > 0; }  // structure and wall
  bool sets_properties() const { return sets_structure() || density_kg_m3 > 0 || set_contents; }
};

struct Overrides {
  std::vector<Override> entries;  // in file order; where two select the same face, each value (class;
                                  // structure with wall; density; contents) comes from the later entry that sets it
  std::string model;              // the model the run was made from (for people; not checked)
  // What the object is, in words ("object": "exercise bike"), as --object
  // takes them: it corrects the identification (identify.h); a run given
  // --object as well keeps --object. "" = what the identify step finds.
  std::string object;
  int faces_total = -1;  // the input's face count; checked when >= 0

  bool empty() const { return entries.empty() && object.empty(); }
  bool changes_labels() const {
    for (const Override& o : entries)
      if (o.label != kUnknownLabel) return true;
    return false;
  }
  bool changes_properties() const {
    for (const Override& o : entries)
      if (o.sets_properties()) return true;
    return false;
  }
};

// Parses the JSON format above; class names are looked up in `table`
// (case-insensitive). Face ranges come back sorted and merged. Fails naming
// the entry and the key for an unknown key or class, a selection that is
// missing, doubled or negative, a "was" on a face selection, a structure
// other than solid/hollow, a wall thickness or density that is not positive
// and finite (or a density above 30,000 kg/m^3, denser than any material),
// contents without a fill from 0 to 1 or with a bad density, a fill of a part
// the entry makes solid, an entry that changes nothing, or a version other
// than kOverridesVersion.
// `origin` names the text in errors (a file path, say).
G2P_API Result<Overrides> parse_overrides(const std::string& json_text, const MaterialTable& table,
                                          const std::string& origin = "overrides");
G2P_API Result<Overrides> read_overrides(const std::string& path, const MaterialTable& table);
// The JSON text of `overrides` (parse_overrides reads it back).
G2P_API std::string overrides_json(const Overrides& overrides, const MaterialTable& table);

// ---- Applying them --------------------------------------------------------------

// The overrides checked against the run they are applied to, as face sets.
struct ResolvedOverrides {
  Overrides overrides;
  // Per face, the last entry that selects it and sets the value, -1 for none:
  std::vector<int> class_entry;      // the class
  std::vector<int> structure_entry;  // solid or hollow, and the wall
  std::vector<int> density_entry;    // the density
  std::vector<int> contents_entry;   // the contents
  std::vector<int> faces;            // per entry: how many faces it selects
};

// Checks every entry against a run's mesh (`num_faces`) and its parts and
// labels (the ones the file was made from: a run's final parts, or the parts
// of a faces.csv) and turns the selections into faces. Fails naming the entry
// when a part or face does not exist, when the face count differs from
// faces_total, when a class is not in `table` (the run's), or when a "was"
// check does not hold (the file was made for another model or run). Entries'
// labels are looked up again in `table` by their class names.
G2P_API Result<ResolvedOverrides> resolve_overrides(const Overrides& overrides, int num_faces,
                                                    const std::vector<Part>& parts, const std::vector<int>& labels,
                                                    const MaterialTable& table);

// The resolved overrides as face selections only (no part indices, no "was"
// checks): per entry, one for its class, one for its structure and wall and
// one for its density, each holding the faces where that value won. They mean the same on the run's labels and still
// hold once the parts have re-formed, so output folders keep them (overrides.json) for the stages that start from the
// folder.
G2P_API Overrides as_face_selections(const ResolvedOverrides& resolved);

// Gives every selected face its new class and re-forms the parts as the
// connected same-class pieces (no fragment merging: parts the overrides do not
// touch stay as they were). Returns one line per entry that changed a class,
// for reports ("entry 1: part 2 (Fabric, 4100 faces) is now Leather").
G2P_API Result<std::vector<std::string>> apply_class_overrides(const ResolvedOverrides& resolved, const Mesh& mesh,
                                                               const FaceGraph& graph, std::vector<int>& labels,
                                                               std::vector<int>& face_part, std::vector<Part>& parts,
                                                               const MaterialTable& table);
// The same on a projection (its labels, parts and confidences).
G2P_API Result<std::vector<std::string>> apply_class_overrides(const ResolvedOverrides& resolved, const Mesh& mesh,
                                                               Projection& projection, const MaterialTable& table);

// An estimator that asks `base`, then sets the structure, wall thickness,
// density and contents the overrides give for the part (from the entries that won any of
// its faces, later entries winning), with ValueSource::kUser and a note
// ("correction: hollow, 4 mm walls, 7000 kg/m^3"). Both must outlive it.
G2P_API std::unique_ptr<PropertyEstimator> make_overriding_estimator(const PropertyEstimator& base,
                                                                     const ResolvedOverrides& resolved);

}  // namespace g2p
