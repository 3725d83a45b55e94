// export: the last stage of Gen2Physics, simulation-ready assets. The
// completed parts with their properties become one rigid body for MuJoCo
// (MJCF), ROS tools (URDF) and Gazebo (SDF 1.9), with per-part meshes beside
// them. Output folders are self-contained and relocatable (relative paths
// only). docs/formats.md shows what each file holds.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "g2p/complete.h"
#include "g2p/decompose.h"
#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/model.h"
#include "g2p/project.h"
#include "g2p/properties.h"
#include "g2p/resting_places.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// One part as the exporters see it.
struct AssetPart {
  int part = -1;         // index into the parts given to make_asset
  std::string name;      // "part_3_Metal", unique, safe in file and XML names
  std::string material;  // class name
  std::array<double, 4> rgba{0.5, 0.5, 0.5, 1.0};
  // Three geometries with distinct roles (docs/formats.md):
  Mesh closed;                    // the closed volume (complete stage): the mass properties come from it
  Mesh visual;                    // the part's own surface from the input: what a viewer draws
  ConvexDecomposition collision;  // convex hulls (decompose stage): what an engine collides
  PartProperties properties;
  MassProperties mass;
};

// A rigid object ready for export.
struct SimulationAsset {
  std::string name;  // model, body and link name
  std::vector<AssetPart> parts;
  MassProperties total;  // about the centre of mass, in the object's frame (+Z up, metres)
  std::vector<std::string> notes;
  // What the object was identified as, as identification_json() writes it
  // (identify.h): report.json's "identification". "" = not identified.
  std::string identification_json;
};

// Gathers the stages' results. Parts without a closed volume are left out
// (noted); at least one must remain. `collision` holds each part's convex
// decomposition (same order as `parts`); when it is empty, every part is
// decomposed here with the default backend (`voxel-cut`, default options).
// A part whose decomposition failed outright collides as its single convex
// hull, and one without even that is left out; both are noted.
G2P_API Result<SimulationAsset> make_asset(const std::string& name, const Mesh& object, const std::vector<Part>& parts,
                                           const Completion& completion, const PropertiesReport& report,
                                           const MaterialTable& table,
                                           const std::vector<ConvexDecomposition>& collision = {});

struct ExportOptions {
  bool free_joint = true;  // MJCF: the body floats (a free joint); false: fixed to the world
  // MuJoCo has one friction coefficient per geom (plus torsional and rolling):
  // the class's dynamic (sliding) coefficient by default, else the static one.
  bool use_static_friction = false;
  // Also write each part's closed volume (meshes/NAME_closed.obj). It can be
  // dense (a grid-based completion of a 12-triangle cube has a million
  // triangles) and no format references it; for inspection only.
  bool write_closed_volumes = false;
  // MuJoCo contacts scaled to the object (mujoco_contacts(), docs/formats.md#contacts-scaled-to-the-object):
  // the contact time constant and the time step from the object's
  // smallest side and its speed when dropped from its own height, and soft
  // classes' rolling and torsional friction. false: every geom gets the
  // properties' solref and solimp as they are, and MuJoCo's own time step.
  bool scale_contacts = true;
  // The largest share of the object's smallest side it may sink into a
  // floor when dropped from its own height (the rule's target, 0 to 0.5).
  double contact_sink = 0.02;
  // MJCF <option timestep>, s; 0: from the contacts (half the shortest
  // contact time constant, at most MuJoCo's 0.002).
  double timestep_s = 0.0;
};

// What the MJCF writer gives MuJoCo for contacts: the time step and each
// part's contact parameters, from mujoco_contacts().
struct PartContact {
  std::array<double, 2> solref{0.02, 1.0};                   // time constant s, damping ratio
  std::array<double, 5> solimp{0.9, 0.95, 0.001, 0.5, 2.0};  // dmin dmax width (m) midpoint power
  std::array<double, 3> friction{0.5, 0.005, 0.0001};        // sliding; torsional and rolling, m
  int condim = 3;                                            // 3: sliding only; 6: torsional and rolling too
  double solmix = 1.0;  // weight of this geom's solref/solimp against the other geom's
  bool soft = false;    // a soft class (Fabric, Leather, Rubber, Foam)
  bool scaled = false;  // solref/solimp from the rule (false: the properties' own)
};
struct MujocoContacts {
  double timestep_s = 0.002;      // MJCF <option timestep>
  double smallest_side_m = 0.0;   // of the collision geometry's bounds
  double height_m = 0.0;          // its extent along +Z: the drop height of the rule
  double impact_speed_m_s = 0.0;  // sqrt(2 g height)
  double timeconst_s = 0.02;      // the rule's contact time constant, s
  // MJCF <option cone="elliptic" impratio>: friction as hard as the contact
  // is soft, so that a ball on a gently sloping seat stops instead of
  // creeping and rolling off (MuJoCo's default pyramidal cone with impratio 1
  // lets it slip; docs/formats.md#contacts-scaled-to-the-object). Set by the rule.
  bool elliptic_cone = false;
  double impratio = 1.0;
  std::vector<PartContact> parts;  // one per SimulationAsset::parts, same order
};
// The contact rule (docs/formats.md#contacts-scaled-to-the-object). With the object's smallest
// side s, height h and impact speed v = sqrt(2 g h), a critically damped
// contact of time constant tc sinks about v tc sqrt(dmax) / e on landing, so
// tc = e * contact_sink * s / (v sqrt(dmax)), between 0.5 ms and MuJoCo's
// 0.02 s; the time step is tc / 2 (MuJoCo: the time constant at least twice
// the time step), at most 0.002 s. Margins stay 0 (MuJoCo's default).
// Soft classes add torsional and rolling friction (condim 6). A part whose
// contact values came from an estimator or a person (contact_source not
// kTable) keeps its solref and solimp. The rule's geoms carry solmix 1000, so
// their solref and solimp win over a floor's MuJoCo defaults (MuJoCo mixes the
// two geoms' values weighted by solmix; friction and condim take the larger).
G2P_API MujocoContacts mujoco_contacts(const SimulationAsset& asset, const ExportOptions& options = {});

// The properties report as written beside an asset (report.json): the
// estimate's notes plus the export's (parts left out, decompositions that
// fell back).
G2P_API PropertiesReport with_export_notes(const PropertiesReport& report, const SimulationAsset& asset);

// report.json beside an asset: report_json() with each exported part's three
// geometries under "geometry" (docs/report-schema.md): the closed volume
// (triangles, volume), the visual mesh (triangles, file) and the collision
// hulls (backend, count, vertices, files, volume against the closed volume,
// mean and largest distance from the part, seconds, fallback and notes).
G2P_API std::string asset_report_json(const PropertiesReport& report, const SimulationAsset& asset,
                                      const MaterialTable& table);
G2P_API Status write_asset_report(const std::string& path, const PropertiesReport& report, const SimulationAsset& asset,
                                  const MaterialTable& table);

// The texts of the three formats. Each part has one collision shape per
// convex hull, meshes/NAME_hull_K.obj, and one visual mesh,
// meshes/NAME_visual.obj, that does not collide (MJCF: contype and
// conaffinity 0, geom group 2; hulls in group 3).
G2P_API std::string mjcf_text(const SimulationAsset& asset, const ExportOptions& options = {});
G2P_API Result<std::string> urdf_text(const SimulationAsset& asset);  // through urdfdom's model and writer
G2P_API std::string sdf_text(const SimulationAsset& asset);

// Writes DIR/NAME.xml, DIR/NAME.urdf and/or DIR/NAME.sdf (formats "mjcf",
// "urdf", "sdf") and DIR/meshes/. Every file is written under a temporary
// name and renamed.
G2P_API Status write_asset(const std::string& dir, const SimulationAsset& asset,
                           const std::vector<std::string>& formats, const ExportOptions& options = {});

// A GLB of the object for engines and viewers that read glTF: one node per
// part with the input's own meshes, UVs and materials (base colour and
// metallic-roughness factors and textures, alpha mode), the part's physical
// properties in the node's `extras.g2p`, the object's totals in the root
// node's, and each part's convex hulls as nodes named NAME_hull_K
// (extras.g2p: collision = true, part, hull) without a material. The glTF
// physics extensions are not ratified yet, so none is written. glTF's frame is +Y up:
// positions, centres of mass and inertia tensors are rotated from libg2p's
// +Z up (x, y, z) -> (x, z, -y). docs/formats.md lists the fields.
G2P_API Status write_glb(const std::string& path, const Model& model, const std::vector<Part>& parts,
                         const SimulationAsset& asset);

// ---- Validation in a real engine ---------------------------------------------

// What MuJoCo makes of an MJCF file: the body's mass properties as the engine
// compiled them, and a drop onto a plane.
struct EngineCheck {
  double mass_kg = 0.0;
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();     // in the body frame
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();  // ascending, kg m^2
  // Drop: released from rest with its lowest point `drop_height_m` above a
  // plane, simulated for `drop_seconds`.
  bool dropped = false;
  bool finite = false;            // no NaN or blow-up
  double lowest_point_m = 0.0;    // min over the run of the lowest collision-mesh vertex's height
  double resting_lowest_m = 0.0;  // the lowest vertex's height at the end (soft contacts: slightly < 0)
  double final_speed_m_s = 0.0;   // of the centre of mass at the end
  double final_height_m = 0.0;    // of the centre of mass at the end
  // What the engine warned of during the drop: a full contact or constraint
  // buffer (contacts were dropped: too many hulls touching at once for the
  // engine's default <size nconmax>), bad accelerations. Empty when clean.
  std::vector<std::string> warnings;
  std::string engine;  // "MuJoCo 2.2.2"
};

// Whether libg2p was built with MuJoCo.
G2P_API bool have_mujoco();

// Loads an MJCF file written by write_asset into MuJoCo and runs the drop.
// Unavailable when libg2p was built without MuJoCo.
G2P_API Result<EngineCheck> check_in_mujoco(const std::string& mjcf_path, double drop_height_m = 0.2,
                                            double drop_seconds = 2.0);

// ---- Contacts in a real engine ---------------------------------------------

// Probe balls dropped onto the object, fixed in place, to see where an engine
// lets things rest on it: in a bowl, on a seat, in a channel.
struct ContactCheckOptions {
  int grid = 5;  // balls per side of a grid over the object's top view (0: only `points` and the places)
  // Further start positions (x, y) in the object's frame, metres: a ball
  // over a bowl's centre, say.
  std::vector<Eigen::Vector2d> points;
  // Also drop balls over each resting place (resting_places.h: the seats,
  // table tops and cavities seen from above) and report per place how many
  // stayed.
  bool places = true;
  RestingPlaceOptions place_options;   // probe_clearance_m is set to the ball's radius
  double ball_radius_m = 0.0;          // 0: 2 % of the object's longest side, at least 5 mm
  double ball_density_kg_m3 = 1000.0;  // water
  // The balls are a user's: MuJoCo's default sphere geom (sliding friction 1,
  // torsional 0.005 m, rolling 0.0001 m, condim 3, default solref and
  // solimp), so what holds them is the object's contact parameters. The
  // floor, the check's own, adds rolling friction so that a ball on it stops.
  double ball_friction = 1.0;  // sliding friction of the balls (MuJoCo combines with the max)
  // Rolling friction of the balls, m: 0 keeps MuJoCo's default ball (condim 3,
  // 0.0001 m); more gives them condim 6 and that lever, so that a ball on a
  // hard level surface stops rolling (what the check did before #62).
  double ball_rolling_friction_m = 0.0;
  double seconds = 3.0;           // simulated time, s
  double rest_speed_m_s = 0.005;  // a ball slower than this at the end is at rest
  double drop_height_m = 0.2;     // the free object's drop onto a plane (check_in_mujoco)
};

// One ball: where it started and where it came to rest.
struct BallProbe {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();  // x, y over the object (its frame), m
  Eigen::Vector3d rest = Eigen::Vector3d::Zero();   // centre at the end, in the object's frame, m
  double radius_m = 0.0;
  double height_above_floor_m = 0.0;  // of its lowest point; the floor is at the object's lowest point
  double final_speed_m_s = 0.0;
  bool at_rest = false;    // final speed under ContactCheckOptions::rest_speed_m_s
  bool on_object = false;  // touching one of the object's collision geoms at the end
  bool on_floor = false;   // touching the floor at the end
  int place = -1;          // ContactCheck::places index it was dropped over; -1: the grid or a point
  int rests_in = -1;       // the place it is in at the end, touching the object; -1: none
};

// One resting place and what the balls dropped over it did.
struct PlaceProbe {
  RestingPlace place;
  int dropped = 0;  // balls dropped over it
  int stayed = 0;   // of those, in it at the end and at rest
};

struct ContactCheck {
  std::vector<BallProbe> balls;
  std::vector<PlaceProbe> places;     // ContactCheckOptions::places: cavities, then surfaces
  HeightMap height_map;               // the collision geometry seen from above (the places' cells)
  Eigen::AlignedBox3d object_bounds;  // of the collision geometry, object's frame, m
  EngineCheck drop;                   // the free object dropped onto a plane (not run when the MJCF is --fixed)
  bool object_above_plane = false;    // after the drop, nothing of it more than 1 cm below the plane
  std::string engine;                 // "MuJoCo 2.2.2"
  // Every ball at rest and the object above the plane.
  bool stable() const {
    for (const BallProbe& b : balls)
      if (!b.at_rest) return false;
    return object_above_plane;
  }
};

// Loads an MJCF written by write_asset, fixes the body in place over a floor
// at its lowest point, drops probe balls onto it (they collide with the
// object's collision geoms and the floor, not with each other) and
// simulates; then runs check_in_mujoco's drop of the free object. Nothing is
// written beside the user's files. Unavailable without MuJoCo.
G2P_API Result<ContactCheck> check_contacts_in_mujoco(const std::string& mjcf_path,
                                                      const ContactCheckOptions& options = {});
// The check as JSON (`g2p validate --contact --json`), and as the table
// `g2p validate --contact` prints (lines ending in a newline; `options` as
// the check ran with).
G2P_API std::string contact_check_json(const ContactCheck& check, const std::string& mjcf_path);
G2P_API std::string contact_check_text(const ContactCheck& check, const std::string& mjcf_path,
                                       const ContactCheckOptions& options);

// ---- A whole export folder (g2p validate DIR) ------------------------------

// The folder's one MJCF file; none, or several, is an error naming them.
G2P_API Result<std::string> find_folder_mjcf(const std::string& dir);

// The folder's MJCF in MuJoCo (check_in_mujoco) beside its report.json.
struct FolderCheck {
  std::string mjcf;  // the file checked
  EngineCheck engine;
  bool has_report = false;  // report.json read; the report_ numbers below are its
  double report_mass_kg = 0.0;
  Eigen::Vector3d report_center_of_mass = Eigen::Vector3d::Zero();
  Eigen::Vector3d report_principal_moments = Eigen::Vector3d::Zero();
  // The engine's mass to 1e-6 relative, centre of mass to 1 um and principal
  // moments to 1e-6 relative of the report's (true without a report).
  bool numbers_match = true;
  // Dropped: finite, resting no more than 1 cm into the plane, no engine
  // warnings (true when the MJCF fixes the body and nothing is dropped).
  bool drop_ok = true;
  double drop_height_m = 0.0, drop_seconds = 0.0;  // as asked
  bool pass() const { return numbers_match && drop_ok; }
};
// What `g2p validate` prints: the engine's numbers beside the report's, the
// drop, the engine's warnings, then PASS or FAIL.
G2P_API std::string folder_check_text(const FolderCheck& check);
G2P_API Result<FolderCheck> check_folder_in_mujoco(const std::string& dir, double drop_height_m = 0.2,
                                                   double drop_seconds = 2.0);

}  // namespace g2p
