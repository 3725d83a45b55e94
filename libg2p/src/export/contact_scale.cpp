// mujoco_contacts: MuJoCo's contact parameters and time step scaled to the
// object (issue #50; docs/formats.md#contacts-scaled-to-the-object states the rule and its sources).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <initializer_list>
#include <string>

#include "core/ascii.h"
#include "g2p/export.h"

namespace g2p {
namespace {

constexpr double kGravity_m_s2 = 9.81;
constexpr double kMujocoTimeconst_s = 0.02;  // MuJoCo's default solref time constant
constexpr double kMujocoTimestep_s = 0.002;  // MuJoCo's default <option timestep>
constexpr double kMinTimeconst_s = 0.0005;   // below this, the time step would be 0.25 ms or less
constexpr double kSolmix = 1000.0;           // the object's solref/solimp win over a default floor's
// Friction constraints ten times as hard as the contact's normal: MuJoCo's
// documentation suggests larger values "to prevent slip"; 10 holds balls of
// 1 to 5 cm on SheenChair's and GlamVelvetSofa's seats (formats.md).
constexpr double kImpratio = 10.0;
// Soft classes: a ball pressed into them meets a lever against rolling and
// twisting. Upholstery (a cushion, a leather seat, foam) holds it in the
// dimple it presses: 2 cm, enough for a ball of 5 cm to stop on a seat that
// slopes 20 degrees or less, and a lever no tyre should have; rubber (a
// tyre, a mat) 5 mm, a rolling resistance of 0.017 for a 30 cm wheel. libg2p
// estimates, chosen on the shared and generated seats
// (docs/formats.md#contacts-scaled-to-the-object).
constexpr double kSoftTorsional_m = 0.02;
constexpr double kCushionRolling_m = 0.02;
constexpr double kRubberRolling_m = 0.005;
constexpr double kTorsional_m = 0.005;  // MuJoCo's defaults for the others
constexpr double kRolling_m = 0.0001;

// Whether the class is one of `names` (lower case), whatever the case.
bool is_one_of(const std::string& name, std::initializer_list<const char*> names) {
  const std::string n = detail::lower_case(name);
  for (const char* candidate : names)
    if (n == candidate) return true;
  return false;
}
bool is_cushion_class(const std::string& name) { return is_one_of(name, {"fabric", "leather", "foam"}); }
bool is_soft_class(const std::string& name) { return is_cushion_class(name) || is_one_of(name, {"rubber"}); }

Eigen::AlignedBox3d collision_bounds(const SimulationAsset& asset) {
  Eigen::AlignedBox3d box;
  for (const AssetPart& p : asset.parts) {
    for (const Mesh& hull : p.collision.hulls)
      for (const Eigen::Vector3f& v : hull.positions) box.extend(v.cast<double>());
    if (p.collision.hulls.empty())
      for (const Eigen::Vector3f& v : p.closed.positions) box.extend(v.cast<double>());
  }
  return box;
}

}  // namespace

MujocoContacts mujoco_contacts(const SimulationAsset& asset, const ExportOptions& options) {
  MujocoContacts out;
  const Eigen::AlignedBox3d box = collision_bounds(asset);
  const Eigen::Vector3d size = box.isEmpty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(box.sizes());
  out.smallest_side_m = std::max(size.minCoeff(), 1e-4);
  out.height_m = std::max(size.z(), 1e-4);
  out.impact_speed_m_s = std::sqrt(2.0 * kGravity_m_s2 * out.height_m);
  const double sink = std::clamp(options.contact_sink, 1e-3, 0.5);
  const double dmax = 0.95;  // MuJoCo's default solimp[1], kept
  // A critically damped spring of time constant tc met at speed v sinks at
  // most v tc sqrt(dmax) / e (MuJoCo's contact is the spring k = 1 / (dmax tc)^2
  // per unit mass, b = 2 / (dmax tc), weighted by the impedance d ~ dmax).
  out.timeconst_s = std::clamp(std::exp(1.0) * sink * out.smallest_side_m / (out.impact_speed_m_s * std::sqrt(dmax)),
                               kMinTimeconst_s, kMujocoTimeconst_s);
  if (options.scale_contacts) {
    out.elliptic_cone = true;
    out.impratio = kImpratio;
  }
  double shortest = kMujocoTimeconst_s;
  for (const AssetPart& p : asset.parts) {
    const PartProperties& pp = p.properties;
    PartContact c;
    c.friction = {options.use_static_friction ? pp.friction_static : pp.friction_dynamic, kTorsional_m, kRolling_m};
    c.solref = pp.solref;
    c.solimp = pp.solimp;
    if (options.scale_contacts) {
      c.soft = is_soft_class(p.material);
      if (c.soft) {
        c.friction[1] = kSoftTorsional_m;
        c.friction[2] = is_cushion_class(p.material) ? kCushionRolling_m : kRubberRolling_m;
        c.condim = 6;
      }
      c.scaled = pp.contact_source == ValueSource::kTable;
      if (c.scaled) {
        c.solref = {out.timeconst_s, 1.0};
        // The impedance reaches dmax within the sink the rule allows (at
        // most MuJoCo's 1 mm).
        c.solimp = {0.9, dmax, std::min(0.001, sink * out.smallest_side_m), 0.5, 2.0};
        c.solmix = kSolmix;
      }
    }
    if (c.solref[0] > 0) shortest = std::min(shortest, c.solref[0]);
    out.parts.push_back(c);
  }
  if (options.timestep_s > 0)
    out.timestep_s = options.timestep_s;
  else
    out.timestep_s = options.scale_contacts ? std::min(kMujocoTimestep_s, 0.5 * shortest) : kMujocoTimestep_s;
  return out;
}

}  // namespace g2p
