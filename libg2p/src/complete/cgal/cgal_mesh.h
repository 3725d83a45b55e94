// Private to the GPL component g2p::cgal: the CGAL types its completers use
// and the small helpers they share. Included only by its two translation
// units (alpha_wrap_completer.cpp, fill_completer.cpp).
#pragma once

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "g2p/mesh.h"
#include "g2p/status.h"

namespace g2p::cgal_detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

// A number for notes, four significant digits.
inline std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// A closed CGAL mesh as a libg2p mesh (positions and triangles only).
inline Mesh to_mesh(const SurfaceMesh& sm) {
  Mesh m;
  std::vector<int> index(sm.num_vertices(), -1);  // num_vertices() counts removed ones too
  m.positions.reserve(sm.number_of_vertices());
  for (SurfaceMesh::Vertex_index v : sm.vertices()) {
    index[v.idx()] = static_cast<int>(m.positions.size());
    const Point& p = sm.point(v);
    m.positions.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  }
  m.triangles.reserve(sm.number_of_faces());
  for (SurfaceMesh::Face_index f : sm.faces()) {
    std::array<int, 3> t{};
    int n = 0;
    for (SurfaceMesh::Vertex_index v : CGAL::vertices_around_face(sm.halfedge(f), sm)) {
      if (n < 3) t[static_cast<std::size_t>(n)] = index[v.idx()];
      ++n;
    }
    if (n == 3) m.triangles.emplace_back(t[0], t[1], t[2]);
  }
  return m;
}

}  // namespace g2p::cgal_detail
