// complete: stage 5 of Gen2Physics, every part's surface patch closed into a
// watertight volume, because mass properties need volumes and physics engines
// need closed meshes. The paper calls the HoloPart model (a GPU diffusion
// model); libg2p's default, `partition`, closes the whole object once on a
// grid and splits its interior among the parts by nearest labelled surface,
// so the parts tile the object's volume. Backends are swappable through
// completer_registry(); the CGAL-based ones live in the optional GPL component
// (g2p/complete_cgal.h).
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/project.h"
#include "g2p/registry.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// The object and its parts; all must outlive the call.
// Progress inside a stage, and whether to go on: `fraction` of the stage's
// work in [0, 1], `message` in words ("distances", "part 3/12"). A status
// other than OK (kCancelled from a RunContext) stops the work, which returns
// it. Empty: no one is listening. The pipeline passes one that reports to
// its RunContext.
using StageProgress = std::function<Status(double fraction, const std::string& message)>;

struct CompletionInput {
  const Mesh* mesh = nullptr;                // the whole object's surface (metres)
  const std::vector<Part>* parts = nullptr;  // from the project stage; Part::faces index mesh->triangles
  const MaterialTable* table = nullptr;      // optional: class names in messages and files
  // Optional, per part: the closed surface complete() keeps as given
  // (closed_part_surface; empty where the part is to be completed). A backend
  // need not close those parts (complete() replaces whatever it returns for
  // them); `partition` gives their solids to them and splits only the rest.
  const std::vector<Mesh>* kept = nullptr;
  // Optional, metres: the thinnest solid part the input's faces measure
  // where an earlier pass lost volume (complete() sets it when it tries
  // again). A grid backend closes openings up to this wide, so that a wall
  // of this thickness left open at its edge (a pot without its bottom
  // face) stays solid; `partition` widens its closing radius to 0.6 of it.
  // 0: no hint. Other backends may ignore it.
  double thin_thickness_m = 0.0;
  // Optional: checked between the steps of a backend and between parts; a
  // status other than OK (cancellation) ends complete() with it.
  StageProgress progress;

  bool is_kept(std::size_t part) const {
    return kept != nullptr && part < kept->size() && (*kept)[part].num_faces() > 0;
  }
  Status report(double fraction, const std::string& message) const {
    return progress ? progress(fraction, message) : Status::Ok();
  }
};

// The validation record of one closed mesh.
struct G2P_API MeshChecks {
  bool closed = false;    // every edge has exactly two triangles, wound in opposite directions
  bool manifold = false;  // closed, and the triangles around every vertex form a single fan
  // Enclosed volume above 1e-12 of the bounding-box diagonal cubed (normals
  // point out); a surface folded onto itself (a triangle and its reverse)
  // encloses nothing and is not outward. The mass properties use the same bound.
  bool outward = false;
  bool self_intersection_free = false;
  bool self_intersections_checked = false;  // false when the mesh was too large to test (see notes)
  int num_components = 0;                   // edge-connected pieces
  int num_self_intersections = 0;           // intersecting pairs of non-adjacent triangles found
  double volume_m3 = 0.0;
  double area_m2 = 0.0;
  // Largest distance from a vertex of the closed mesh to the part's own patch
  // (over up to MeshCheckOptions::max_distance_samples vertices), in metres
  // and relative to the patch's bounding-box diagonal; -1 if no patch was given.
  double max_distance_m = -1.0;
  double relative_distance = -1.0;

  // Closed, manifold, outward, positive volume and (when tested) free of
  // self-intersections.
  bool watertight() const;
};

struct MeshCheckOptions {
  int max_faces_for_intersections = 2'000'000;  // larger meshes skip the self-intersection test
  int max_distance_samples = 20'000;            // vertices whose distance to the patch is measured (evenly spread)
};

// Checks a closed-mesh candidate. `patch` (optional) is the surface it should
// stay near, for the distance check.
G2P_API MeshChecks check_closed_mesh(const Mesh& mesh, const Mesh* patch = nullptr,
                                     const MeshCheckOptions& options = {});

// One completed part.
struct CompletedPart {
  int part = -1;  // index into CompletionInput::parts
  int label = kUnknownLabel;
  Mesh mesh;  // closed, outward; positions in the object's frame
  MeshChecks checks;
  std::string backend;             // which backend produced `mesh` (after any fallback)
  std::vector<std::string> notes;  // fallbacks, warnings
  // Checks passed, the distance to the patch is within the completer's
  // tolerance and the volume agrees with the input's (below). A part that
  // fails is kept but flagged; later stages say so.
  bool ok = false;
  // The independent volume check (estimate_volumes): the volume the input's
  // faces enclose that falls to this part, m^3 (-1: no estimate), and how far
  // `checks.volume_m3` lies from it, relative ((ours - input) / input; NaN
  // where the estimate could not judge this part, see CompletionOptions).
  double input_volume_m3 = -1.0;
  double volume_difference = std::numeric_limits<double>::quiet_NaN();
};

struct Completion {
  std::vector<CompletedPart> parts;  // one per input part, same order
  // Volume of the whole closed object where the backend knows it (partition), else 0.
  double object_volume_m3 = 0.0;
  // Sum of the part volumes; with `partition` it equals object_volume_m3 up to
  // the overlap where part borders meet the object's skin.
  double parts_volume_m3 = 0.0;
  double grid_spacing_m = 0.0;  // partition: the grid's cell size; 0 for other backends
  // The volume the input's faces enclose (estimate_volumes), m^3; -1 where
  // they are too open to tell.
  double input_volume_m3 = -1.0;
  int kept_parts = 0;  // parts whose own faces were already closed, kept as they are
  std::vector<std::string> notes;
};

class G2P_API Completer {
 public:
  virtual ~Completer();
  // This backend's settings bound to this instance (settings.h): info()
  // lists them with their values, apply() sets them. Default: none.
  virtual SettingsSpec settings();
  // Applies settings, all or none: a bad key or value leaves the backend as it
  // was. Default: settings().apply(); a backend overrides it only to act on
  // the new values (load a network, make a client).
  virtual Status configure(const BackendSettings& settings);
  // Closes every part of the object. A backend may fail single parts (their
  // CompletedPart::ok = false) without failing the call; complete() below
  // redoes those with a fallback.
  virtual Result<Completion> complete(const CompletionInput& input) const = 0;
};

// Backends by name; libg2p registers "partition" (the default, no CGAL) and
// "external" (a user command such as a HoloPart wrapper, docs/complete.md).
// register_cgal_completers() adds "alpha-wrap" and "fill".
G2P_API Registry<Completer>& completer_registry();
// Creates a backend and applies its settings: completer_registry().make().
inline Result<std::unique_ptr<Completer>> make_completer(const std::string& name,
                                                         const BackendSettings& settings = {}) {
  return completer_registry().make(name, settings);
}

struct CompletionOptions {
  // A part whose own faces already bound a solid (closed_part_surface) is
  // kept as it is, so its volume, mass and inertia are the input's exactly;
  // the completer closes the others. false: the completer closes every part.
  bool keep_closed_parts = true;
  // Vertices closer than this (x the object's bounding-box diagonal) are one
  // vertex when deciding whether a part is closed (as ProjectOptions).
  double weld_tolerance = 1e-6;
  // The independent volume check: a part whose closed volume differs from
  // the input's by more than this fraction fails (ok = false, a note saying
  // by how much). It judges a part whose estimate is its own: at least
  // `volume_check_own_fraction` of it lies between two of the part's faces
  // (a thin board, a rod, a closed shell), not between faces of different
  // parts, where the estimate's split (halfway along each ray) and the
  // completer's (nearest surface) differ by design. <= 0: no check.
  double volume_tolerance = 0.10;
  double volume_check_own_fraction = 0.8;
  int volume_rays = 192;  // rays per side of each of the three ray grids (estimate_volumes)
  // Parts the volume check fails are tried again: the completer once more
  // with the failing parts' thickness as a hint (CompletionInput::
  // thin_thickness_m), and a failing part whose volume lies between its own
  // faces and another part's as a shell of its measured thickness
  // (thin_part_shell). Each is kept only where the parts then agree better
  // with the input's volume. false: the first result stands, flagged.
  bool resolve_thin_parts = true;
};

// Runs `completer`; parts it failed (not ok) are redone by `fallback` (if
// given) and noted. Parts already closed are kept (options.keep_closed_parts;
// when every part is, the completer is not called), and every part's volume
// is checked against the input's (options.volume_tolerance). The result
// always has one entry per part.
G2P_API Result<Completion> complete(const CompletionInput& input, const Completer& completer,
                                    const Completer* fallback = nullptr, const CompletionOptions& options = {});

// The part's faces as a closed solid, when they already are one: vertices
// within `weld_tolerance` (x the bounding-box diagonal of `mesh`) merged,
// degenerate triangles dropped, and the result closed, consistently oriented,
// vertex-manifold and free of self-intersections, with every component
// outward except those inside another (cavities, wound inward). A component
// inside out that no other contains is turned. Empty when the faces are not
// a solid, or not clearly one: open, non-manifold, self-intersecting,
// overlapping components, a nested component wound like the one around it.
G2P_API Mesh closed_part_surface(const Mesh& mesh, const Part& part, double weld_tolerance = 1e-6);

// A thin part closed as a shell of its measured thickness, for a part whose
// volume lies between its own faces and the faces of other parts (a board
// given as its top and bottom faces, two parts with no edge between them):
// its welded faces, a copy of them moved inward along the vertex normals by
// half the distance to the surface behind (where a ray from each vertex
// first meets another part's face or another edge-connected piece of its
// own, as estimate_volumes splits every inside interval halfway), and walls
// along its open edges. Empty where that is not a thin shell: a ray that
// meets nothing, its own piece or a face from outside, an offset deeper than
// a tenth of the part's second-largest extent, or a result not watertight.
G2P_API Mesh thin_part_shell(const Mesh& mesh, const std::vector<Part>& parts, std::size_t part,
                             double weld_tolerance = 1e-6);

// The volume inside the input's faces, estimated without closing them: rays
// cast along each axis through a grid of `rays_per_side` x `rays_per_side`
// points over the bounding box, the crossings paired by winding number (by
// parity where orientation is inconsistent), and every inside interval split
// halfway between the parts of the two faces that bound it. Exact for a
// closed surface up to the grid's sampling; thin parts lose nothing, since
// every ray measures its own thickness. Rays whose crossings do not pair
// (holes, open sheets) are left out and counted.
struct VolumeEstimate {
  double object_m3 = 0.0;
  std::vector<double> part_m3;            // per part
  std::vector<double> part_own_fraction;  // per part: share of part_m3 between two faces of the part itself
  std::vector<int> part_intervals;        // per part: inside intervals that gave it volume
  int rays_hit = 0;                       // rays that crossed the surface
  int rays_paired = 0;                    // of those, rays whose crossings pair up
  // Enough rays paired (90 %) for the estimate to judge.
  bool usable() const { return rays_hit > 0 && rays_paired >= 0.9 * rays_hit; }
};
G2P_API VolumeEstimate estimate_volumes(const Mesh& mesh, const std::vector<Part>& parts, int rays_per_side = 192);

// For completers that close each part on its own from its patch (alpha-wrap,
// fill, external, a learned model such as HoloPart): calls `close` for every
// part with the part's patch. `close` puts the closed mesh in out.mesh (and
// may add notes); an error rejects the part (its message becomes a note; a
// mesh it left is still checked and kept, flagged). Exceptions fail the part
// only. Each mesh is then checked against its patch: the part is ok when
// `close` succeeded, the mesh is watertight and it lies within
// `max_relative_distance` of the patch (x the patch's diagonal).
using ClosePart = std::function<Status(int part, const Mesh& patch, CompletedPart& out)>;
G2P_API Result<Completion> complete_each_part(const CompletionInput& input, const std::string& backend,
                                              double max_relative_distance, const ClosePart& close);

// The part's own faces as a mesh (its open patch), vertices compacted.
G2P_API Mesh part_patch(const Mesh& mesh, const Part& part);

// ---- Output -----------------------------------------------------------------

// Writes DIR/part_<i>_<class>.<ext> for every part and every extension in
// `formats` ("obj", "ply", "stl"), and DIR/completion.json with the checks.
G2P_API Status write_completion(const std::string& dir, const Completion& completion, const MaterialTable& table,
                                const std::vector<std::string>& formats = {"obj"});

}  // namespace g2p
