// properties: stage 6 of Gen2Physics, physical properties of the completed
// parts. This header holds the exact mass properties of closed triangle meshes
// (solid) and of surfaces with a wall thickness (hollow, the paper's
// m = rho * A * t), and the combination of parts into an object. The
// PropertyEstimator interface and its backends arrive with issue #8.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "g2p/export.h"
#include "g2p/mesh.h"
#include "g2p/status.h"

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

// Several parts as one body: masses add, the centre of mass is the weighted
// mean, inertias move to it by the parallel-axis theorem.
G2P_API MassProperties combine(const std::vector<MassProperties>& parts);

}  // namespace g2p
