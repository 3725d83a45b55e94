// Face colours across the views, and the cut of the face graph into regions.
//
// Regions are the components of the face graph after removing every edge
// across a crease (dihedral angle above `crease_deg`), a colour edge (mean
// colours further apart than `colour_step`) or between a seen and an unseen
// face (hidden faces have no colour, and would otherwise join two seen
// regions of different colours behind them); union-find over the kept edges.
// Regions below `min_area_fraction` of the surface then join, smallest first,
// the neighbouring region they share the longest border with (separate
// pieces with no neighbour stay), as the project stage merges fragments.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>

#include "core/srgb.h"
#include "core/union_find.h"
#include "g2p/regions.h"

namespace g2p {
namespace {}  // namespace

FaceColours face_colours(const Mesh& mesh, const std::vector<View>& views) {
  const std::size_t nf = static_cast<std::size_t>(mesh.num_faces());
  FaceColours out;
  out.rgb.assign(nf, Eigen::Vector3f::Zero());
  out.pixels.assign(nf, 0.f);
  std::vector<Eigen::Vector3d> sum(nf, Eigen::Vector3d::Zero());
  for (const View& v : views) {
    const bool base = !v.base_color.empty() && v.base_color.width() == v.face_id.width() &&
                      v.base_color.height() == v.face_id.height() && v.base_color.channels() >= 3;
    const bool shaded = !v.rgb.empty() && v.rgb.width() == v.face_id.width() && v.rgb.height() == v.face_id.height() &&
                        v.rgb.channels() >= 3;
    if (!base && !shaded) continue;
    for (int y = 0; y < v.face_id.height(); ++y)
      for (int x = 0; x < v.face_id.width(); ++x) {
        const int f = v.face_id.at(x, y);
        if (f < 0 || static_cast<std::size_t>(f) >= nf) continue;
        Eigen::Vector3d c;
        if (base)
          c = {v.base_color.at(x, y, 0), v.base_color.at(x, y, 1), v.base_color.at(x, y, 2)};
        else
          c = {detail::srgb_to_linear(v.rgb.at(x, y, 0) / 255.f), detail::srgb_to_linear(v.rgb.at(x, y, 1) / 255.f),
               detail::srgb_to_linear(v.rgb.at(x, y, 2) / 255.f)};
        sum[static_cast<std::size_t>(f)] += c;
        out.pixels[static_cast<std::size_t>(f)] += 1.f;
      }
  }
  for (std::size_t f = 0; f < nf; ++f)
    if (out.pixels[f] > 0.f) out.rgb[f] = (sum[f] / out.pixels[f]).cast<float>();
  return out;
}

Result<Regions> find_regions(const Mesh& mesh, const FaceGraph& graph, const FaceColours& colours,
                             const RegionOptions& options) {
  const int nf = mesh.num_faces();
  if (graph.num_faces() != nf || static_cast<int>(colours.rgb.size()) != nf ||
      static_cast<int>(colours.pixels.size()) != nf || graph.neighbors.size() != graph.shared_edge_m.size() ||
      std::any_of(graph.neighbors.begin(), graph.neighbors.end(), [nf](int g) { return g < 0 || g >= nf; }))
    return Status::InvalidArgument("find_regions: the face graph or the colours are not of this mesh (" +
                                   std::to_string(nf) + " faces)");
  if (!(options.crease_deg >= 0.0 && options.crease_deg <= 180.0) || !(options.colour_step >= 0.0) ||
      !(options.min_area_fraction >= 0.0 && options.min_area_fraction < 1.0))
    return Status::InvalidArgument(
        "find_regions: crease in [0, 180] degrees, colour step >= 0 and min area in [0, 1) expected");
  const std::size_t n = static_cast<std::size_t>(nf);
  std::vector<Eigen::Vector3f> normal(n);
  std::vector<double> area(n);
  double total_area = 0.0;
  for (int f = 0; f < nf; ++f) {
    normal[static_cast<std::size_t>(f)] = face_normal(mesh, f).cast<float>();
    total_area += area[static_cast<std::size_t>(f)] = face_area(mesh, f);
  }
  // At 180 degrees nothing is a crease (rounding can put the dot product of
  // opposite normals below -1).
  const float min_cos =
      options.crease_deg >= 180.0 ? -2.f : static_cast<float>(std::cos(options.crease_deg * M_PI / 180.0));
  const float step2 = static_cast<float>(options.colour_step * options.colour_step);
  detail::UnionFind pieces(n);
  for (int f = 0; f < nf; ++f)
    for (int i = graph.offsets[static_cast<std::size_t>(f)]; i < graph.offsets[static_cast<std::size_t>(f) + 1]; ++i) {
      const int g = graph.neighbors[static_cast<std::size_t>(i)];
      if (g <= f) continue;
      if (normal[static_cast<std::size_t>(f)].dot(normal[static_cast<std::size_t>(g)]) < min_cos) continue;
      const bool f_seen = colours.pixels[static_cast<std::size_t>(f)] > 0.f;
      const bool g_seen = colours.pixels[static_cast<std::size_t>(g)] > 0.f;
      if (f_seen != g_seen) continue;  // hidden faces must not bridge two seen regions
      if (f_seen &&
          (colours.rgb[static_cast<std::size_t>(f)] - colours.rgb[static_cast<std::size_t>(g)]).squaredNorm() > step2)
        continue;
      pieces.unite(f, g);
    }

  // Number the components, then merge the small ones.
  std::vector<int> region(n, -1);
  std::vector<int> root_region(n, -1);
  int count = 0;
  for (int f = 0; f < nf; ++f) {
    const int r = pieces.find(f);
    if (root_region[static_cast<std::size_t>(r)] < 0) root_region[static_cast<std::size_t>(r)] = count++;
    region[static_cast<std::size_t>(f)] = root_region[static_cast<std::size_t>(r)];
  }
  std::vector<double> region_area(static_cast<std::size_t>(count), 0.0);
  for (std::size_t f = 0; f < n; ++f) region_area[static_cast<std::size_t>(region[f])] += area[f];
  // Merging: a union-find over regions, smallest first; each small region
  // joins the neighbour with the longest border (borders counted once over
  // the current roots).
  const double min_area = options.min_area_fraction * total_area;
  detail::UnionFind merged(static_cast<std::size_t>(count));
  if (min_area > 0.0 && count > 1) {
    std::vector<std::vector<int>> faces_of(static_cast<std::size_t>(count));
    for (int f = 0; f < nf; ++f) faces_of[static_cast<std::size_t>(region[static_cast<std::size_t>(f)])].push_back(f);
    std::vector<int> order(static_cast<std::size_t>(count));
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return region_area[static_cast<std::size_t>(a)] < region_area[static_cast<std::size_t>(b)] ||
             (region_area[static_cast<std::size_t>(a)] == region_area[static_cast<std::size_t>(b)] && a < b);
    });
    std::vector<double> border(static_cast<std::size_t>(count), 0.0);
    std::vector<int> touched;
    for (const int r0 : order) {
      const int r = merged.find(r0);
      if (r != r0 || region_area[static_cast<std::size_t>(r)] >= min_area) continue;  // already grown
      touched.clear();
      for (const int f : faces_of[static_cast<std::size_t>(r)])
        for (int i = graph.offsets[static_cast<std::size_t>(f)]; i < graph.offsets[static_cast<std::size_t>(f) + 1];
             ++i) {
          const int other = merged.find(region[static_cast<std::size_t>(graph.neighbors[static_cast<std::size_t>(i)])]);
          if (other == r) continue;
          if (border[static_cast<std::size_t>(other)] == 0.0) touched.push_back(other);
          border[static_cast<std::size_t>(other)] += graph.shared_edge_m[static_cast<std::size_t>(i)] + 1e-12;
        }
      int best = -1;
      for (const int o : touched)
        if (best < 0 || border[static_cast<std::size_t>(o)] > border[static_cast<std::size_t>(best)] ||
            (border[static_cast<std::size_t>(o)] == border[static_cast<std::size_t>(best)] && o < best))
          best = o;
      for (const int o : touched) border[static_cast<std::size_t>(o)] = 0.0;
      if (best < 0) continue;  // a separate small piece: stays
      merged.unite(r, best);
      region_area[static_cast<std::size_t>(best)] += region_area[static_cast<std::size_t>(r)];
      std::vector<int>& into = faces_of[static_cast<std::size_t>(best)];
      std::vector<int>& from = faces_of[static_cast<std::size_t>(r)];
      if (into.size() < from.size()) into.swap(from);  // append the shorter list: no quadratic growth
      into.insert(into.end(), from.begin(), from.end());
      from.clear();
    }
  }
  Regions out;
  out.face_region.assign(n, -1);
  std::vector<int> number(static_cast<std::size_t>(count), -1);
  for (int f = 0; f < nf; ++f) {
    const int r = merged.find(region[static_cast<std::size_t>(f)]);
    if (number[static_cast<std::size_t>(r)] < 0) {
      number[static_cast<std::size_t>(r)] = static_cast<int>(out.regions.size());
      out.regions.emplace_back();
    }
    Region& target = out.regions[static_cast<std::size_t>(number[static_cast<std::size_t>(r)])];
    target.faces.push_back(f);
    target.area_m2 += area[static_cast<std::size_t>(f)];
    out.face_region[static_cast<std::size_t>(f)] = number[static_cast<std::size_t>(r)];
  }
  return out;
}

}  // namespace g2p
