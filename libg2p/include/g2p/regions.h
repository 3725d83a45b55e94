// regions: a material decision per region of the mesh, not per pixel (issue
// #31). The welded face graph is cut where materials usually meet: at creases,
// at colour edges (the colour each face shows across the views) and between
// separate pieces; small regions join their longest-bordering neighbour. Each
// region is then described by evidence a single pixel does not have: the
// network's votes summed over the region, its colour statistics across views,
// its size, shape and place in the object, and the object's overall votes.
// A classifier trained on the training libraries (OpenCV random trees,
// tools/training/train_regions) decides the region's class; the `regions`
// refiner (refine.h) applies it in the pipeline.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/project.h"
#include "g2p/render.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// ---- Face colours -------------------------------------------------------------

// What each face looks like across the views: the mean linear RGB of the
// pixels that saw it (the base-colour buffer where the views have one, else
// the shaded sRGB colour made linear) and how many pixels that was.
struct FaceColours {
  std::vector<Eigen::Vector3f> rgb;  // per face; 0 for unseen faces
  std::vector<float> pixels;         // per face; 0 = no view saw it
};

G2P_API FaceColours face_colours(const Mesh& mesh, const std::vector<View>& views);

// ---- Regions ------------------------------------------------------------------

struct RegionOptions {
  double crease_deg = 40.0;          // neighbours meeting at a sharper dihedral angle (degrees) are cut apart
  double colour_step = 0.1;          // ...and neighbours whose colours differ by more (linear RGB, Euclidean)
  double min_area_fraction = 0.002;  // smaller regions join the neighbour with the longest shared border
};

struct Region {
  std::vector<int> faces;  // indices into Mesh::triangles
  double area_m2 = 0.0;
};

struct Regions {
  std::vector<int> face_region;  // per face
  std::vector<Region> regions;
};

// Regions of `mesh` over its face graph. Unseen faces have no colour: they
// form regions of their own (cut at creases), which join a seen neighbour
// when small. Separate pieces are always separate regions (a region
// never spans two components of the graph).
G2P_API Result<Regions> find_regions(const Mesh& mesh, const FaceGraph& graph, const FaceColours& colours,
                                     const RegionOptions& options = {});

// ---- Features -------------------------------------------------------------------

// The feature names, in column order, for a table of `num_classes` classes:
// vote_<class> (the region's area-weighted vote shares), object_vote_<class>
// (the whole object's), then the colour, size, shape and position features
// documented in docs/regions.md.
G2P_API std::vector<std::string> region_feature_names(const MaterialTable& table);

// One row of region_feature_names(table).size() values per region, row-major.
G2P_API Result<std::vector<float>> region_features(const Mesh& mesh, const Regions& regions, const FaceVotes& votes,
                                                   const FaceColours& colours, const MaterialTable& table);

// ---- Classifier -----------------------------------------------------------------

// Random trees over region features (OpenCV's ml module, kept private), with
// a model card (JSON: format "g2p-region-classifier", the class and feature
// names it was trained with, the trees file beside it, and how it was made).
class G2P_API RegionClassifier {
 public:
  RegionClassifier();
  ~RegionClassifier();
  RegionClassifier(RegionClassifier&&) noexcept;
  RegionClassifier& operator=(RegionClassifier&&) noexcept;

  // Reads a card and its trees; fails, naming the file, when either is
  // missing or the card's classes and features are not those of `table`.
  static Result<RegionClassifier> load(const std::string& card_path, const MaterialTable& table);

  // Class probabilities per region (rows x classes, the trees' vote shares).
  Result<std::vector<float>> predict(const std::vector<float>& features, int rows) const;

  int num_classes() const;
  int num_features() const;
  const std::string& card_path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct RegionTrainOptions {
  int trees = 200;             // random trees
  int max_depth = 16;          // per tree
  int min_samples = 4;         // fewest samples a node splits
  int features_per_split = 0;  // 0: the square root of the feature count
};

// Trains random trees on `rows` samples (features as region_features writes
// them, a class index per sample, a weight per sample) and writes the trees
// to `trees_path` (OpenCV's format; .yml.gz compresses).
G2P_API Status train_region_classifier(const std::vector<float>& features, const std::vector<int>& labels,
                                       const std::vector<float>& weights, int num_features, int num_classes,
                                       const RegionTrainOptions& options, const std::string& trees_path);

// The shipped card, g2p-regions.json, in the model folders the `learned`
// segmenter searches ($G2P_MODEL_DIR, the source tree, the install prefix);
// empty if none has it.
G2P_API std::string shipped_region_card();

}  // namespace g2p
