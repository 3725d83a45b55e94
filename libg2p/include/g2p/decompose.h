// decompose: the collision geometry an engine wants. Physics engines collide
// meshes as convex shapes (MuJoCo, PhysX and Bullet take the convex hull of a
// mesh geom, at most 255 vertices in PhysX and Bullet), so a concave part (a
// bowl, a chair's seat and backrest) needs an approximate convex
// decomposition: a few convex hulls whose union stays close to the part's
// closed volume. This step runs after `complete`; the exporters write one
// collision shape per hull and the input's own faces as the visual mesh,
// while the mass properties stay those of the closed volume.
//
// Backends are swappable through decomposer_registry(): `voxel-cut` (the
// default: a voxel grid split recursively by the axis-aligned planes that most
// reduce concavity, after V-HACD, Mamou 2016) and `hull` (one convex hull per
// part). docs/decompose.md compares them.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "g2p/complete.h"
#include "g2p/mesh.h"
#include "g2p/project.h"
#include "g2p/registry.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// What every backend honours.
struct DecomposeOptions {
  int max_hulls = 16;              // per part, 1..256; a part that is already convex gets one
  int max_vertices_per_hull = 64;  // 4..255; engines cap a hull at 255 (PhysX, Bullet)
  // Concavities shallower than this (metres) are left alone. 0: the
  // backend's own tolerance relative to the part, and decompose_parts() with
  // the object uses 1 % of the object's bounding-box diagonal, so that small
  // parts are not cut for dents nothing could rest in.
  double min_depth_m = 0.0;  // >= 0
  // Fidelity is measured on a voxel grid with this many cells along the part's
  // longest side: the distance below is exact to half a cell.
  int measure_resolution = 64;  // 16..512
  // Coverage: a part's hulls should stand no farther outside its closed
  // volume (max_distance_m below), and leave no point of its surface
  // farther outside them (uncovered_max_m), than this share of the object's
  // bounding-box diagonal (the part's when decompose_part() runs alone).
  // decompose_parts() decomposes a part that spent its whole max_hulls
  // budget and still misses it again with twice the budget, while the
  // object's hulls stay within max_hulls_per_object; a part that still
  // misses gets a note. docs/decompose.md gives the measurements behind the
  // default.
  double coverage_tolerance = 0.03;  // 0..1
  // The most hulls decompose_parts() gives a whole object by raising part
  // budgets (the first pass's max_hulls per part is never cut back); 0: no
  // budget is raised.
  int max_hulls_per_object = 256;  // 0..65536
};

// The collision geometry of one part.
struct ConvexDecomposition {
  // Closed, outward, convex triangle meshes, each with at most
  // max_vertices_per_hull vertices, in the part's frame (metres).
  std::vector<Mesh> hulls;
  std::string backend;  // the caller's name for the backend (the pipeline: its registry name); "hull" after a fallback
  bool fell_back = false;  // the backend failed and the part got its single convex hull (see notes)
  // Fidelity, measured the same way for every backend.
  double part_volume_m3 = 0.0;   // the closed volume's
  double hulls_volume_m3 = 0.0;  // sum over hulls (overlaps counted twice)
  // How far the hulls' surfaces stand outside the part's closed volume: the
  // mean and the largest over surface samples, in metres (0 where a sample
  // lies inside the volume). Contacts happen up to this far from the part.
  double mean_distance_m = 0.0;
  double max_distance_m = 0.0;
  // The other way: how far the part's closed surface lies outside the union
  // of its hulls (surface the hulls leave uncovered), the mean and the
  // largest over about 20,000 area samples of the surface (and every vertex
  // of a closed mesh of at most 20,000), in metres: the exact distance to
  // the nearest hull at each sample, 0 where a hull holds it. Objects pass
  // into the part this deep before they touch a hull.
  double uncovered_mean_m = 0.0;
  double uncovered_max_m = 0.0;
  int hull_budget = 0;  // the max_hulls the hulls were made with (decompose_parts() may raise it)
  // The distance both largest distances above should stay within
  // (coverage_tolerance, in metres for this part); 0 where not checked.
  double coverage_tolerance_m = 0.0;
  double seconds = 0.0;            // wall time of the decomposition and its measurement
  std::vector<std::string> notes;  // fallbacks, degenerate input, budgets that bound the result
};

class G2P_API Decomposer {
 public:
  virtual ~Decomposer();
  // This backend's settings bound to this instance (settings.h): info()
  // lists them with their values, apply() sets them. Default: none.
  virtual SettingsSpec settings();
  // Applies settings, all or none: a bad key or value leaves the backend as it
  // was. Default: settings().apply(); a backend overrides it only to act on
  // the new values (load a network, make a client).
  virtual Status configure(const BackendSettings& settings);
  // Splits one closed, outward mesh (a completed part) into convex pieces:
  // fills `hulls` (at most options.max_hulls, each within the vertex budget
  // after convex_hull's reduction) and may add notes. decompose_part() below
  // measures the result and handles failure. decompose_parts() calls it from
  // several threads at once.
  virtual Status decompose(const Mesh& closed, const DecomposeOptions& options, ConvexDecomposition& out) const = 0;
};

// Backends by name; libg2p registers "voxel-cut" (the default) and "hull".
G2P_API Registry<Decomposer>& decomposer_registry();
// Creates a backend and applies its settings: decomposer_registry().make().
inline Result<std::unique_ptr<Decomposer>> make_decomposer(const std::string& name,
                                                           const BackendSettings& settings = {}) {
  return decomposer_registry().make(name, settings);
}
G2P_API Status validate(const DecomposeOptions& options);  // ranges above; names the field's CLI flag

// Runs `decomposer` on one part and measures the result. When the backend
// fails or returns an invalid set (no hulls, too many, a hull over the vertex
// budget), the part gets its single convex hull instead, with a note saying
// why. Fails only when not even a hull exists (fewer than 4 points not on one
// plane: a flat or empty part); the message says so.
G2P_API Result<ConvexDecomposition> decompose_part(const Mesh& closed, const Decomposer& decomposer,
                                                   const DecomposeOptions& options = {});

// Every part of a completion, in parallel; `backend` names the decomposer
// in the results. A part that cannot be decomposed at all (no closed volume,
// flat) gets no hulls and a note saying why; the call itself never fails.
// A part whose hulls miss options.coverage_tolerance after spending its
// whole budget is decomposed again with twice the budget (up to 256), the
// worst part first, while the object's hulls stay within
// options.max_hulls_per_object; the better result is kept, and a part that
// still misses gets a note.
// With the object and its parts (the completion's input), no hull gets more
// vertices than the part's own faces have (at least 4), so that no
// collision mesh is denser than the input it stands for, and min_depth_m
// 0 means 1 % of the object's bounding-box diagonal. `progress` hears of each
// finished part (from the worker threads, one call at a time); once it
// returns an error (a cancelled run) no further part starts, and those left
// get no hulls and the note "not decomposed: <its message>".
G2P_API std::vector<ConvexDecomposition> decompose_parts(const Completion& completion, const Decomposer& decomposer,
                                                         const DecomposeOptions& options = {},
                                                         const std::string& backend = "custom",
                                                         const Mesh* object = nullptr,
                                                         const std::vector<Part>* parts = nullptr,
                                                         const StageProgress& progress = {});

// The convex hull of `points` as a closed, outward triangle mesh. With
// max_vertices > 0 and a hull of more vertices, the hull is rebuilt from a
// subset chosen greedily (each step adds the point farthest outside the hull
// so far), so it stays inside the full hull and loses as little as the budget
// allows. Fails for fewer than 4 points or points on one plane.
G2P_API Result<Mesh> convex_hull(const std::vector<Eigen::Vector3d>& points, int max_vertices = 0);

// The volume a closed, outward mesh encloses, in m^3 (divergence theorem).
G2P_API double enclosed_volume(const Mesh& mesh);

}  // namespace g2p
