// Objects exported the way a user's run exports them, for the tests that load
// the written files in an engine (MuJoCo in exporters_test.cpp, DART in
// dart_test.cpp).
#pragma once

#include <string>
#include <vector>

#include "g2p/complete.h"
#include "g2p/export.h"
#include "g2p/io.h"
#include "g2p/project.h"
#include "g2p/properties.h"

namespace g2p::test {

// A model labelled with its ground truth, through the partition completer,
// the table estimator and make_asset: each face gets its material's class
// from `labels_json` (labels.json's form, `{"models": {KEY: {"labels":
// {"0": "Wood", ...}}}}`; a material marked unknown becomes Other), and
// same-class faces that touch form one part.
struct TruthExport {
  Model model;
  std::vector<Part> parts;
  Completion completion;
  PropertiesReport report;
  SimulationAsset asset;
};
TruthExport export_with_truth(const std::string& model_path, const std::string& key, const std::string& labels_json);

// A shared asset (../shared/assets/NAME) with its labels.json ground truth.
TruthExport export_shared_asset(const std::string& name);

// The seats among a contact check's resting places: the largest upward-facing
// surface between a quarter and three quarters of the object's height above
// the floor (a chair's or a sofa's seat, not its backrest's top or its feet),
// and any other there at least half as large (a sofa's second cushion, not an
// armrest).
std::vector<const PlaceProbe*> seats(const ContactCheck& check);

}  // namespace g2p::test
