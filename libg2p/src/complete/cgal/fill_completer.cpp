// The `fill` completer (GPL-3.0-or-later component g2p::cgal): each part's
// patch keeps its own triangles and every hole in it is filled with
// CGAL::Polygon_mesh_processing::triangulate_refine_and_fair_hole. This suits
// parts whose holes are small openings where they met their neighbours; a
// part with a hole wider than max_relative_hole of its diagonal, a patch that
// is not an orientable manifold surface, or a fill that is not watertight is
// left not ok, so complete() redoes it with the fallback.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iterator>
#include <string>
#include <vector>

#include "complete/cgal/cgal_mesh.h"
#include "g2p/complete_cgal.h"

namespace g2p {
namespace {

using cgal_detail::number;
using cgal_detail::Point;
using cgal_detail::SurfaceMesh;
using cgal_detail::to_mesh;

using Halfedge = SurfaceMesh::Halfedge_index;
namespace PMP = CGAL::Polygon_mesh_processing;

// Loads the patch as a Surface_mesh through CGAL's polygon-soup repair and
// orientation; an error message when it is not an orientable manifold.
std::string load_patch(const Mesh& patch, SurfaceMesh& sm) {
  std::vector<Point> points;
  points.reserve(patch.positions.size());
  for (const Eigen::Vector3f& q : patch.positions) points.emplace_back(q.x(), q.y(), q.z());
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(patch.triangles.size());
  for (const Eigen::Vector3i& t : patch.triangles)
    polygons.push_back(
        {static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]), static_cast<std::size_t>(t[2])});
  PMP::repair_polygon_soup(points, polygons);  // merges duplicate points, drops degenerate and repeated triangles
  if (polygons.empty()) return "no triangles are left after repairing the patch (all degenerate)";
  if (!PMP::orient_polygon_soup(points, polygons))
    return "the patch is not an orientable manifold surface (CGAL had to split vertices to orient it)";
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) return "the patch is not a manifold polygon mesh";
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
  if (!CGAL::is_triangle_mesh(sm) || !sm.is_valid(false)) return "the patch did not load as a valid triangle mesh";
  return {};
}

class FillCompleter final : public Completer {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("fill")
        .number("max_relative_hole", max_relative_hole_, Range::above(0), "",
                "holes wider than this (x the part's diagonal) are not filled")
        .integer("fairing_continuity", fairing_continuity_, 0, 2, "", "smoothness of the fill: 0, 1 or 2")
        .number("max_relative_distance", max_relative_distance_, Range::above(0), "",
                "a part whose surface strays farther from its patch (x the patch's diagonal) fails");
  }

  Result<Completion> complete(const CompletionInput& input) const override {
    return complete_each_part(input, "fill", max_relative_distance_,
                              [&](int, const Mesh& patch, CompletedPart& out) { return fill_part(patch, out); });
  }

 private:
  // Closes one patch into out.mesh, or says why it cannot.
  Status fill_part(const Mesh& patch, CompletedPart& out) const {
    const double diag = patch.num_faces() > 0 ? bounds(patch).diagonal().norm() : 0.0;
    if (!(diag > 0) || !std::isfinite(diag))
      return Status::InvalidArgument("fill: the part has no faces of positive extent");
    SurfaceMesh sm;
    if (std::string why = load_patch(patch, sm); !why.empty()) return Status::InvalidArgument("fill: " + why);
    std::vector<Halfedge> holes;
    PMP::extract_boundary_cycles(sm, std::back_inserter(holes));

    // Every hole must be small next to the part before any is filled.
    double widest = 0.0;
    for (Halfedge h : holes) {
      Eigen::AlignedBox3d box;
      for (Halfedge e : CGAL::halfedges_around_face(h, sm)) {
        const Point& q = sm.point(sm.source(e));
        box.extend(Eigen::Vector3d(q.x(), q.y(), q.z()));
      }
      widest = std::max(widest, box.diagonal().norm() / diag);
    }
    if (widest > max_relative_hole_)
      return Status::Unavailable("fill: the widest of the " + std::to_string(holes.size()) + " holes spans " +
                                 number(widest) + " of the part's diagonal, more than max_relative_hole " +
                                 number(max_relative_hole_));

    int added_faces = 0, unfaired = 0;
    for (std::size_t i = 0; i < holes.size(); ++i) {
      std::vector<SurfaceMesh::Face_index> faces;
      std::vector<SurfaceMesh::Vertex_index> vertices;
      const auto r = PMP::triangulate_refine_and_fair_hole(
          sm, holes[i], std::back_inserter(faces), std::back_inserter(vertices),
          CGAL::parameters::fairing_continuity(static_cast<unsigned>(fairing_continuity_)));
      if (faces.empty())
        return Status::Unavailable("fill: CGAL found no triangulation for hole " + std::to_string(i + 1) + " of " +
                                   std::to_string(holes.size()));
      added_faces += static_cast<int>(faces.size());
      if (!std::get<0>(r) && !vertices.empty()) ++unfaired;
    }
    if (!CGAL::is_closed(sm)) return Status::Unavailable("fill: the patch is still open after filling its holes");
    bool reversed = false;
    if (PMP::volume(sm) < 0) {
      PMP::reverse_face_orientations(sm);
      reversed = true;
    }
    out.mesh = to_mesh(sm);
    if (holes.empty()) {
      out.notes.push_back("fill: the patch was already closed");
    } else {
      out.notes.push_back("fill: filled " + std::to_string(holes.size()) + " hole(s) with " +
                          std::to_string(added_faces) + " triangles (widest " + number(widest) +
                          " of the diagonal, fairing continuity C" + std::to_string(fairing_continuity_) + ")");
    }
    if (unfaired > 0)
      out.notes.push_back("fill: fairing failed for " + std::to_string(unfaired) + " hole(s); they are refined only");
    if (reversed) out.notes.push_back("fill: reversed the faces to point outward");

    return Status::Ok();
  }

  double max_relative_hole_ = 0.3;
  double max_relative_distance_ = 0.25;
  int fairing_continuity_ = 1;
};

}  // namespace

std::unique_ptr<Completer> make_fill_completer() { return std::make_unique<FillCompleter>(); }

}  // namespace g2p
