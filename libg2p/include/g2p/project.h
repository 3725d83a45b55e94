// project: stage 3 of Gen2Physics, the 2D-to-3D consistency projection.
// Every labelled pixel of every view votes for the material of the face it
// sees (through the face-ID buffer); each face takes the class with the most
// votes (the paper's Eq. 1), which filters single-view errors. Faces no view
// saw take the majority of their labelled neighbours (flood fill). The mesh is
// then split into connected same-material parts.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/model.h"
#include "g2p/render.h"
#include "g2p/segment.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// ---- Face graph ---------------------------------------------------------------

// Which faces share an edge, after welding vertices that lie within a
// tolerance of each other (UV seams and split normals duplicate vertices; the
// surface is still connected there). Compressed rows: the neighbours of face f
// are neighbors[offsets[f] .. offsets[f + 1]), each with the length of the
// shared edge in metres.
struct FaceGraph {
  std::vector<int> offsets;
  std::vector<int> neighbors;
  std::vector<float> shared_edge_m;
  std::vector<int> welded_vertex;  // per vertex: its representative after welding

  int num_faces() const { return offsets.empty() ? 0 : static_cast<int>(offsets.size()) - 1; }
};

// `weld_tolerance` is relative to the bounding-box diagonal (1e-6: 1 um on a
// 1 m object).
G2P_API Result<FaceGraph> build_face_graph(const Mesh& mesh, double weld_tolerance = 1e-6);

// ---- Voting -----------------------------------------------------------------

enum class VoteMode {
  kHard,  // one vote per pixel for its label (the paper's Eq. 1)
  kSoft,  // each pixel adds its class probabilities (needs LabelMap::probabilities)
};

struct VoteOptions {
  VoteMode mode = VoteMode::kHard;
  bool weight_by_angle = false;      // times |cos| of the angle between the face normal and the pixel's ray
  bool weight_by_footprint = false;  // times the surface area the pixel covers (m^2), so votes measure area
};

// Per-face vote histograms over all views. Only faces some view saw have a
// histogram row (large meshes are mostly hidden inside), so memory follows the
// visible faces, not the mesh.
struct FaceVotes {
  int num_classes = 0;
  std::vector<int> row;          // per face: its row in `histogram`, or -1 if no view saw it
  std::vector<float> histogram;  // rows x num_classes, row-major
  std::vector<float> total;      // per face, the sum of its votes (0 for unseen faces)

  // The face's votes per class, or nullptr if no view saw it.
  const float* of(int face) const {
    const int r = row[static_cast<std::size_t>(face)];
    return r < 0 ? nullptr : histogram.data() + static_cast<std::size_t>(r) * num_classes;
  }
};

G2P_API Result<FaceVotes> vote(const Mesh& mesh, const std::vector<View>& views, const std::vector<LabelMap>& maps,
                               int num_classes, const VoteOptions& options = {});

// ---- Labels -----------------------------------------------------------------

struct FaceLabels {
  std::vector<int> label;          // per face; kUnknownLabel only if no face at all received a vote
  std::vector<float> confidence;   // the winner's share of the face's votes; 0 for filled faces
  std::vector<std::uint8_t> seen;  // 1 if some view voted for the face
};

// Each voted face takes its most-voted class (ties: the lower class index).
// Unseen faces then take the majority label of their labelled neighbours,
// wave by wave (ties: the neighbour class sharing the longest border, then
// the lower index); faces in components with no labelled face take the label
// of the nearest labelled face (centroid distance).
G2P_API FaceLabels assign_labels(const Mesh& mesh, const FaceGraph& graph, const FaceVotes& votes);

// ---- Parts ------------------------------------------------------------------

struct Part {
  int label = kUnknownLabel;
  std::vector<int> faces;  // indices into Mesh::triangles (their FaceSource gives the caller's faces)
  double area_m2 = 0.0;
};

struct PartitionOptions {
  // Parts smaller than this fraction of the total area merge into the
  // neighbouring part they share the longest border with (0 = keep all)...
  double min_part_area_fraction = 0.001;
  // ...unless their votes were confident: a fragment whose area-weighted mean
  // confidence exceeds this is a real small part (metal feet, screws) and
  // stays. Only used when partition() is given the confidences.
  double merge_max_confidence = 0.6;
};

// Connected components of same-label faces over the face graph; `labels` is
// updated where small fragments were merged. face_part gets each face's part.
// `confidence` (per face, e.g. FaceLabels::confidence; 0 for filled faces)
// protects confidently voted fragments from merging; null merges every small
// fragment.
G2P_API std::vector<Part> partition(const Mesh& mesh, const FaceGraph& graph, std::vector<int>& labels,
                                    std::vector<int>& face_part, const PartitionOptions& options = {},
                                    const std::vector<float>* confidence = nullptr);

// ---- The whole stage ----------------------------------------------------------

struct ProjectOptions {
  VoteOptions vote;
  double weld_tolerance = 1e-6;  // relative to the bounding-box diagonal
  PartitionOptions partition;
};

struct Projection {
  FaceGraph graph;
  FaceVotes votes;
  FaceLabels labels;  // after fragment merging
  std::vector<Part> parts;
  std::vector<int> face_part;  // per face
};

G2P_API Result<Projection> project(const Mesh& mesh, const std::vector<View>& views, const std::vector<LabelMap>& maps,
                                   int num_classes, const ProjectOptions& options = {});

// The face labels seen through a view: the input the VLM refinement looks at.
G2P_API LabelMap render_face_labels(const View& view, const std::vector<int>& face_labels);

// ---- Files ------------------------------------------------------------------

// faces.csv: one row per face of the input in input order, columns
// source_mesh,source_face,source_material,source_material_name,label,confidence,area_m2,part
// (label is the class name, empty when unknown).
G2P_API Status write_faces_csv(const std::string& path, const Model& model, const Projection& projection,
                               const MaterialTable& table);

// Reads faces.csv back for `mesh` (written by write_faces_csv for the same
// model): per-face labels (class names looked up in `table`) and the parts
// they form. Fails, naming the line, when the row count, a source column or a
// class name does not match.
struct FacesFile {
  std::vector<int> labels;     // per face
  std::vector<int> face_part;  // per face
  std::vector<Part> parts;     // indexed by the file's part column
};
G2P_API Result<FacesFile> read_faces_csv(const std::string& path, const Mesh& mesh, const MaterialTable& table);

// A binary PLY of the mesh with per-face colours of the table (to look at).
G2P_API Status write_labelled_ply(const std::string& path, const Mesh& mesh, const std::vector<int>& face_labels,
                                  const MaterialTable& table);

// The project stage's folder: DIR/faces.csv, DIR/labelled.ply, DIR/parts.json
// and DIR/projected/ (the face labels seen through every view, the input of
// the refine stage and of a person checking the result; none without views).
G2P_API Status write_projection(const std::string& dir, const Model& model, const std::vector<View>& views,
                                const Projection& projection, const MaterialTable& table);

}  // namespace g2p
