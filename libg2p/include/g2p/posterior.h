// posterior: what the object's kind decides where its surface cannot show it
// (issue #65). The paper asks its vision-language model for each part's
// structure and wall thickness with the object in view; offline, the kind
// (identify.h) is the context. Two steps, both only for an object whose kind
// the run acts on:
//  - fit_classes_to_kind, after refine: a class may cover only the share of
//    the object's surface the kind allows it (a car's Rubber is its tyres, a
//    small share); the largest parts of a class beyond its share take the
//    most probable class the kind allows, from their own votes.
//  - fit_mass_to_kind, after properties: every part has the structures its
//    class allows (solid, a shell of a wall from the class's set, a fill of
//    foam or fabric, at the low, nominal or high density of its class), each
//    with a prior; the kind's mass range, scaled to the object's size, is the
//    likelihood of the total. The assignment with the highest posterior is
//    chosen and weighed physically (each part its volume times its density,
//    never a scaled total); importance sampling gives the median and 90 %
//    interval of the object and of each part.
// Where the kind is unknown, fit_mass_to_bulk_density judges the mass the
// same way against what everyday objects weigh per cubic metre of their
// closed outline (a weak belief: mostly an interval). Both intervals count
// the parts' other probable classes from the views' votes (ClassEvidence).
// docs/properties.md#the-kinds-mass-posterior states the rules.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "g2p/complete.h"
#include "g2p/identify.h"
#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/project.h"
#include "g2p/properties.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

struct PosteriorOptions {
  // Within a kind, mass grows as (size / typical size)^size_exponent, the
  // size held within the kind's usual longest sides. 2.0 is
  // the slope of log mass on log longest side over the 47 validation models
  // whose name names a kind (data/mass-ranges/val.json; docs/accuracy.md).
  double size_exponent = 2.0;
  // The kind's mass range is read as this central share of a log-normal
  // belief about the real object's mass, centred on the range's geometric
  // centre. An estimate already inside the range stands as it is; one
  // outside takes the assignment with the highest posterior.
  double range_share = 0.9;  // (0, 1)
  // Largest share of the object's surface area a class may cover when the
  // kind does not list it; 1 = no limit (a hammer's handle may be plastic).
  // A listed class may cover what its role's KindMaterial::max_share says
  // (a car's tyres 0.2), its main (first) role's class everything.
  double unlisted_share = 1.0;  // [0, 1]
  // A part that takes another class takes one the kind lists: its main
  // role's at any share, another role's up to its max_share or, where the
  // table gives none, up to this share of the surface (a car body voted
  // Rubber is not its seats' Fabric).
  double minor_share = 0.35;  // [0, 1]
  // Prior weights of the structures a part may have, relative to the one the
  // estimator chose from the geometry (weight 1).
  double other_wall_weight = 0.5;       // the same structure, another wall from the class's set
  double other_structure_weight = 0.3;  // solid for hollow or hollow for solid
  double other_density_weight = 0.5;    // the class's lowest or highest density instead of its nominal
  double fill_weight = 0.5;             // foam or fabric over a frame, a share of its closed volume filled
  // Where the kind is unknown: the object's mass over its parts' closed
  // volume is log-normal about bulk_density_kg_m3 with bulk_density_log_sd
  // (natural log), as measured on the 56 validation models
  // (scripts/mass_set/bulk_density.py; docs/accuracy.md).
  double bulk_density_kg_m3 = 474.0;
  double bulk_density_log_sd = 1.26;
  // Whether that belief may change a part's structure (as the kind's does),
  // or gives the intervals only (the default: deciding took an unnamed
  // hammer's steel head, 3,850 kg/m^3 with its handle, for too dense and
  // weighed it 0.60 kg instead of 1.457; docs/accuracy.md).
  bool bulk_density_decides = false;
  // The intervals also draw each part's other classes that its faces' votes
  // give at least this probability (and the kind allows at the part's share),
  // weighed by their votes; the chosen assignment keeps the part's class.
  double class_min_probability = 0.1;  // (0, 1]; 1 = the part's class only
  int samples = 4000;                  // importance samples for the intervals; 0 = no intervals
  std::uint32_t seed = 1;              // the sampler's, for reproducible intervals
};

// The most of the object's surface area each class of `table` may cover for
// an object of `kind` (per label; 1 = no limit).
G2P_API std::vector<double> kind_class_shares(const ObjectKind& kind, const MaterialTable& table,
                                              const PosteriorOptions& options = {});

// Relabels the parts (and their faces in `projection.labels`) whose class
// covers more of the surface than the kind allows, largest part first, each
// to the most probable class of its faces' votes (`projection.votes`; the
// kind's main class where the votes name none) that the kind allows at the
// share it would then reach. Parts with `pinned[i]` (a person's class) are
// left alone. Returns one note per change ("part 3 (0.62 of the surface):
// Rubber -> Metal: a car's Rubber (tyres) covers at most 20 % of it").
G2P_API std::vector<std::string> fit_classes_to_kind(Projection& projection, const ObjectKind& kind,
                                                     const MaterialTable& table, const std::vector<bool>& pinned = {},
                                                     const PosteriorOptions& options = {});

// The part's class probabilities from its faces' votes (pixel counts, so a
// face weighs as much as it was seen); empty when no view saw the part.
G2P_API std::vector<double> part_class_probabilities(const FaceVotes& votes, const Part& part, int num_classes);

// What the views said of each part's class, for the intervals (optional).
struct ClassEvidence {
  const FaceVotes* votes = nullptr;  // the project stage's votes; null: each part's class is certain
  std::vector<bool> pinned;          // per part: a person gave its class (not in doubt); empty: none
};

// One way a part may be: its class, structure and density.
struct PartHypothesis {
  Structure structure = Structure::kSolid;
  double wall_thickness_m = 0.0;  // hollow: the shell's thickness
  bool double_walled = false;     // hollow: both faces of the wall modelled, each carries t / 2
  double fill = 1.0;              // solid: the share of the closed volume filled (foam, stuffing)
  double density_kg_m3 = 0.0;     // of the material (a fill weighs fill x density)
  double mass_kg = 0.0;           // this part's mass so
  double prior = 1.0;             // relative prior weight
  bool estimated = false;         // the estimator's own answer
  std::string words;              // "hollow, 2 mm walls", "solid, 60 % filled", "solid"
  // Another class the votes give the part (its index in the table), drawn for
  // the intervals only: the chosen assignment keeps the part's class. -1: the
  // part's own class.
  int label = -1;
};

struct PartPosterior {
  int part = -1;
  std::vector<PartHypothesis> hypotheses;  // [0] is the estimator's
  int chosen = 0;                          // into hypotheses
  bool pinned = false;                     // a person's structure or density: kept
  double median_kg = 0.0, p05_kg = 0.0, p95_kg = 0.0;
  std::string note;  // why it changed, in words; "" when the estimator's answer stands
};

struct MassPosterior {
  std::string kind;       // the kind's name; "" when judged by bulk density
  std::string judged_by;  // in words: "a chair's 2.5-12 kg at 0.95 m", "everyday objects' ..."

  double longest_side_m = 0.0;      // the object's size it was judged at
  double range_kg[2] = {0.0, 0.0};  // the kind's range scaled to that size (the belief's central share)
  double hidden_fraction = 0.0;     // the kind's hidden mass, a share of the whole (added where the body is hollow)
  int body = -1;                    // the part that holds it
  std::vector<PartPosterior> parts;
  double mass_kg = 0.0;       // the chosen assignment's total (hidden mass included)
  double estimated_kg = 0.0;  // the estimator's total, before
  double median_kg = 0.0, p05_kg = 0.0, p95_kg = 0.0;
  bool in_range = false;           // the chosen total lies in range_kg
  double effective_samples = 0.0;  // of the importance sampler
  std::vector<std::string> notes;  // the choice in words; the part that breaks the range when none reaches it
  // Some part's chosen hypothesis is not the estimator's.
  bool changed() const {
    for (const PartPosterior& p : parts)
      if (p.chosen != 0) return true;
    return false;
  }
};

// Judges `report` (estimate_properties or estimate_properties_of_kind for
// `kind`) against the kind's mass at `longest_side_m`. Parts whose structure,
// wall or density a person set (ValueSource::kUser) keep them. Fails for an
// object longer or shorter than 1.25 times the kind's usual longest sides
// (not one of the kind as the table knows it: a toy train called a train).
G2P_API Result<MassPosterior> fit_mass_to_kind(const std::vector<Part>& parts, const Completion& completion,
                                               const MaterialTable& table, const PropertiesReport& report,
                                               const ObjectKind& kind, double longest_side_m,
                                               const PosteriorOptions& options = {}, const ClassEvidence& classes = {});

// The same for an object of unknown kind, against everyday objects' bulk
// density (PosteriorOptions::bulk_density_kg_m3) times the parts' closed
// volume. Fails when no part closed.
G2P_API Result<MassPosterior> fit_mass_to_bulk_density(const std::vector<Part>& parts, const Completion& completion,
                                                       const MaterialTable& table, const PropertiesReport& report,
                                                       const PosteriorOptions& options = {},
                                                       const ClassEvidence& classes = {});

// An estimator that answers as `base` except where `posterior` chose another
// hypothesis, which it gives with source "kind" and the posterior's note.
// `base` and `posterior` must outlive it.
G2P_API std::unique_ptr<PropertyEstimator> make_posterior_estimator(const PropertyEstimator& base,
                                                                    const MassPosterior& posterior);

// Writes the posterior's intervals into `report` (PartReport and
// PropertiesReport mass_median_kg, mass_p05_kg, mass_p95_kg, mass_judged_by;
// kind_range_kg for a kind) and its notes.
G2P_API void apply_intervals(const MassPosterior& posterior, PropertiesReport& report);

}  // namespace g2p
