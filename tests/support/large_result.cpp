#include "support/large_result.h"

#include <cmath>

namespace g2p::test {

PipelineResult large_grid_result(int nx, int ny) {
  PipelineResult r;
  r.table = MaterialTable::paper_default();
  Mesh& mesh = r.model.mesh;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x)
      mesh.positions.emplace_back(x * 1e-3f, y * 1e-3f, 0.01f * std::sin(x * 0.05f) * std::cos(y * 0.05f));
  Part left{r.table.find("Wood"), {}, 0.0}, right{r.table.find("Metal"), {}, 0.0};
  for (int y = 0; y + 1 < ny; ++y)
    for (int x = 0; x + 1 < nx; ++x) {
      const int v = y * nx + x;
      Part& part = x < nx / 2 ? left : right;
      part.faces.push_back(mesh.num_faces());
      mesh.triangles.emplace_back(v, v + 1, v + nx + 1);
      part.faces.push_back(mesh.num_faces());
      mesh.triangles.emplace_back(v, v + nx + 1, v + nx);
    }
  r.projection.parts = {left, right};
  r.asset.name = "grid";
  return r;
}

}  // namespace g2p::test
