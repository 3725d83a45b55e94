// properties: stage 6 of Gen2Physics, physical properties of the completed
// parts. A PropertyEstimator gives each part its density, structure (solid or
// hollow, with a wall thickness) and contact parameters; the exact mass
// properties of closed triangle meshes (solid) or of their surfaces with a
// wall thickness (hollow, the paper's m = rho * A * t) follow, and the parts
// combine into the object. docs/properties.md; report.json's fields in
// docs/report-schema.md.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "g2p/complete.h"
#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/model.h"
#include "g2p/project.h"
#include "g2p/registry.h"
#include "g2p/render.h"
#include "g2p/status.h"
#include "g2p/visibility.h"
#include "g2p/vlm.h"

namespace g2p {

struct G2P_API MassProperties {
  double mass_kg = 0.0;
  double volume_m3 = 0.0;  // enclosed volume (solid) or surface area x thickness (shell)
  double area_m2 = 0.0;    // surface area
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();  // metres, in the mesh's frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();         // kg m^2 about the centre of mass, mesh axes

  // Principal moments (ascending, kg m^2) and axes (columns, a right-handed rotation).
  Eigen::Vector3d principal_moments() const;
  Eigen::Matrix3d principal_axes() const;
};

// A closed, consistently wound (outward) triangle mesh filled with material of
// `density_kg_m3`: volume integrals by the divergence theorem, one tetrahedron
// per triangle to a reference point (Tonon 2004, "Explicit exact formulas for
// the 3-D tetrahedron inertia tensor"), in double precision. Fails for an
// empty mesh, a non-positive density or a non-positive enclosed volume (open
// or inward-wound meshes).
G2P_API Result<MassProperties> solid_mass_properties(const Mesh& mesh, double density_kg_m3);

// The mesh's surface as a shell of `thickness_m` (thin-shell approximation:
// mass rho * A * t spread over the surface; the surface need not be closed).
G2P_API Result<MassProperties> shell_mass_properties(const Mesh& mesh, double density_kg_m3, double thickness_m);

// `volume_m3` of a fill (a liquid, sand, grain) of `density_kg_m3` settled in
// the bottom of a closed, outward mesh under gravity along -Z: the part of the
// enclosed volume below the level z = h at which that volume lies below it
// (found by bisection to 1e-9 of the enclosed volume). Exact for the clipped
// volume: every triangle is clipped to z <= h and closes a tetrahedron with a
// reference point on the level plane, so the flat surface of the fill adds
// nothing. `volume_m3` from 0 (exclusive) to the enclosed volume; fails
// otherwise, and as solid_mass_properties fails.
G2P_API Result<MassProperties> fill_mass_properties(const Mesh& closed, double density_kg_m3, double volume_m3);

// Several parts as one body: masses add, the centre of mass is the weighted
// mean, inertias move to it by the parallel-axis theorem.
G2P_API MassProperties combine(const std::vector<MassProperties>& parts);

// ---- Walls ------------------------------------------------------------------

// How thick a part's material is, measured by rays cast from points of its
// patch into its closed volume: the distance to where the ray leaves the
// volume (the part's local thickness) and, where the object has another
// surface inside the volume before that (an inner wall: a bottle modelled
// with its inside), the distance to it.
struct WallMeasurement {
  int rays = 0;               // rays that entered the closed volume
  int inner_hits = 0;         // of those, rays that met an inner surface first
  double thickness_m = 0.0;   // median local thickness of the closed volume
  double inner_wall_m = 0.0;  // median distance to the inner surface, over the rays that met one
  double inner_fraction() const { return rays > 0 ? static_cast<double>(inner_hits) / rays : 0.0; }
};

// `max_rays` sample points, area-weighted and deterministic. A patch point
// counts as inside the closed volume (an inner surface) only if it lies
// deeper than `surface_tolerance_m` (the completion's grid spacing: closed
// surfaces from a grid sit up to a cell off the patch).
G2P_API Result<WallMeasurement> measure_walls(const Mesh& object, const Part& part, const Mesh& closed,
                                              int max_rays = 2000, double surface_tolerance_m = 0.0);

// Ray queries against one surface (an Embree BVH), built once and shared:
// every part's wall measurement casts rays at the same object, and building
// the structure for a million-triangle object takes a few tenths of a second.
class G2P_API SurfaceRays {
 public:
  static Result<std::shared_ptr<const SurfaceRays>> build(const Mesh& mesh);
  ~SurfaceRays();
  SurfaceRays(const SurfaceRays&) = delete;
  SurfaceRays& operator=(const SurfaceRays&) = delete;
  int num_faces() const { return num_faces_; }  // of the mesh it was built from

 private:
  SurfaceRays() = default;
  friend Result<WallMeasurement> measure_walls(const SurfaceRays&, const Mesh&, const Part&, const Mesh&, int, double);
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int num_faces_ = 0;
};

// The same with `object_rays` built from `object` beforehand.
G2P_API Result<WallMeasurement> measure_walls(const SurfaceRays& object_rays, const Mesh& object, const Part& part,
                                              const Mesh& closed, int max_rays = 2000,
                                              double surface_tolerance_m = 0.0);

// ---- Estimating properties ----------------------------------------------------

// Where a value came from.
// kKind: the object's kind (identify.h's object table).
enum class ValueSource { kTable, kGeometry, kVlm, kUser, kKind };
G2P_API const char* to_string(ValueSource source);  // "table", "geometry", "vlm", "user", "kind"

struct PartProperties {
  int label = kUnknownLabel;
  double density_kg_m3 = 0.0;      // nominal
  double density_min_kg_m3 = 0.0;  // plausible range, for the mass range
  double density_max_kg_m3 = 0.0;
  Structure structure = Structure::kSolid;
  double wall_thickness_m = 0.0;  // the shell's thickness when hollow
  // Hollow parts weigh rho * A * t over their own surface (the patch, not the
  // closed volume's faces inside the object). When the model has both faces
  // of the wall (inner surfaces found by measure_walls), each carries t / 2.
  bool double_walled = false;
  // Contents: a hollow part's cavity (its closed volume less its walls) holds
  // a fill of this density up to `contents_fill` of its volume, settled at the
  // bottom under gravity along -Z (a bottle of water, a tank half full).
  // A fill of 0 is empty, the default; a solid part has no cavity and keeps
  // none (a note says so, beginning with kContentsLeftOut).
  double contents_density_kg_m3 = 1000.0;  // kg/m^3; water
  double contents_fill = 0.0;              // share of the cavity, 0 to 1
  double friction_static = 0.5;            // Coulomb coefficients
  double friction_dynamic = 0.5;
  double restitution = 0.5;
  // MuJoCo contact softness (MJCF solref = time constant s and damping ratio;
  // solimp = dmin dmax width midpoint power), MuJoCo's defaults unless an
  // estimator has better.
  std::array<double, 2> solref{0.02, 1.0};
  std::array<double, 5> solimp{0.9, 0.95, 0.001, 0.5, 2.0};
  ValueSource density_source = ValueSource::kTable;
  ValueSource structure_source = ValueSource::kTable;
  ValueSource thickness_source = ValueSource::kTable;
  ValueSource contact_source = ValueSource::kTable;
  WallMeasurement walls;           // what the geometry said
  std::vector<std::string> notes;  // the rule applied, fallbacks
};

// What an estimator looks at for one part; all must outlive the call.
struct PropertyInput {
  const Mesh* object = nullptr;              // the whole object's surface
  const Part* part = nullptr;                // the part's faces in `object`
  const CompletedPart* completed = nullptr;  // its closed volume (complete stage)
  const MaterialTable* table = nullptr;
  const std::vector<View>* views = nullptr;  // optional: renders of the object, for the vlm backend
  // Optional object context: all parts and their closed volumes (same order).
  const std::vector<Part>* all_parts = nullptr;
  const Completion* all_completed = nullptr;
  // Optional: rays against `object`, built once by estimate_properties for all parts.
  const SurfaceRays* object_rays = nullptr;
};

class G2P_API PropertyEstimator {
 public:
  virtual ~PropertyEstimator();
  // This backend's settings bound to this instance (settings.h): info()
  // lists them with their values, apply() sets them. Default: none.
  virtual SettingsSpec settings();
  // Applies settings, all or none: a bad key or value leaves the backend as it
  // was. Default: settings().apply(); a backend overrides it only to act on
  // the new values (load a network, make a client).
  virtual Status configure(const BackendSettings& settings);
  virtual Result<PartProperties> estimate(const PropertyInput& input) const = 0;
};

// Backends by name: "table" (the default: the material table's values, solid
// or hollow decided by measure_walls and the part's size, docs/properties.md
// states the rule) and
// "vlm" (asks a vision-language model, falls back to "table").
G2P_API Registry<PropertyEstimator>& estimator_registry();
// Creates a backend and applies its settings: estimator_registry().make().
inline Result<std::unique_ptr<PropertyEstimator>> make_estimator(const std::string& name,
                                                                 const BackendSettings& settings = {}) {
  return estimator_registry().make(name, settings);
}
// The vlm estimator with a client of the caller's.
G2P_API std::unique_ptr<PropertyEstimator> make_vlm_estimator(std::shared_ptr<const VlmClient> client);

// ---- The whole stage ----------------------------------------------------------

struct PartReport {
  int part = -1;
  PartProperties properties;
  MassProperties mass;      // nominal density; the walls and the contents together
  MassProperties contents;  // the contents alone (zero mass when empty)
  double mass_min_kg = 0.0, mass_max_kg = 0.0;
  // The mass posterior (posterior.h): median and 90 % interval; 0 where not judged.
  double mass_median_kg = 0.0, mass_p05_kg = 0.0, mass_p95_kg = 0.0;
  bool completed_ok = false;  // the complete stage's checks passed
};

struct PropertiesReport {
  std::vector<PartReport> parts;
  MassProperties object;  // all parts combined, about the object's centre of mass
  double mass_min_kg = 0.0, mass_max_kg = 0.0;
  // The mass posterior (posterior.h): the object's median and 90 % interval,
  // what it was judged by in words, and the kind's mass range at the
  // object's size; 0 and "" where not judged (kind_range_kg: no kind).
  double mass_median_kg = 0.0, mass_p05_kg = 0.0, mass_p95_kg = 0.0;
  std::string mass_judged_by;
  double kind_range_kg[2] = {0.0, 0.0};
  // The object's size: estimate_properties sets the extent from the object's
  // mesh; callers that loaded a model set the rest (object_size(model)).
  ObjectSize size;
  std::vector<std::string> notes;
};

// The words that begin the note of a part whose contents were asked for but
// not given ("contents left out: the part is solid ..."), in its notes and
// (after "part N: ") in the report's.
inline constexpr const char* kContentsLeftOut = "contents left out: ";

// Estimates every completed part and combines them. Parts whose completion
// failed (no closed mesh) are left out of the totals and noted. `progress`
// hears of each part weighed; an error it returns (a cancelled run) ends the
// call with it before the next part.
G2P_API Result<PropertiesReport> estimate_properties(const Mesh& object, const std::vector<Part>& parts,
                                                     const Completion& completion, const MaterialTable& table,
                                                     const PropertyEstimator& estimator,
                                                     const std::vector<View>* views = nullptr,
                                                     const StageProgress& progress = {});

// report.json (docs/report-schema.md).
G2P_API std::string report_json(const PropertiesReport& report, const MaterialTable& table);
G2P_API Status write_report(const std::string& path, const PropertiesReport& report, const MaterialTable& table);

}  // namespace g2p
