// The `alpha-wrap` completer (GPL-3.0-or-later component g2p::cgal): each
// part's open patch is wrapped with CGAL::alpha_wrap_3, which always returns
// a watertight, 2-manifold mesh free of self-intersections that strictly
// contains the patch. alpha (the largest gap the wrap does not enter) and the
// offset (its distance from the patch) scale with the part's bounding-box
// diagonal. Also registers the CGAL completers (register_cgal_completers).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "complete/cgal/cgal_mesh.h"
#include "core/union_find.h"
#include "g2p/complete_cgal.h"

namespace g2p {
namespace {

using cgal_detail::number;
using cgal_detail::Point;
using cgal_detail::SurfaceMesh;
using cgal_detail::to_mesh;

namespace PMP = CGAL::Polygon_mesh_processing;

// The holes of a patch: loops of edges with one triangle, after welding
// vertices at equal positions (imported meshes split vertices at seams).
struct Holes {
  int count = 0;
  double widest = 0.0;  // largest bounding-box diagonal of one hole, metres
};

Holes find_holes(const Mesh& patch) {
  struct PositionHash {
    std::size_t operator()(const std::array<float, 3>& p) const {
      std::size_t h = 0;
      for (float c : p) h = h * 1000003u ^ std::hash<float>()(c);
      return h;
    }
  };
  std::unordered_map<std::array<float, 3>, int, PositionHash> welded;
  std::vector<int> id(patch.positions.size());
  std::vector<Eigen::Vector3d> where;
  for (std::size_t i = 0; i < patch.positions.size(); ++i) {
    const Eigen::Vector3f& q = patch.positions[i];
    const auto [it, added] = welded.emplace(std::array<float, 3>{q.x(), q.y(), q.z()}, static_cast<int>(where.size()));
    if (added) where.push_back(q.cast<double>());
    id[i] = it->second;
  }
  std::unordered_map<std::uint64_t, int> uses;  // undirected edge -> triangles on it
  for (const Eigen::Vector3i& t : patch.triangles)
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint64_t>(id[static_cast<std::size_t>(t[k])]);
      const auto b = static_cast<std::uint64_t>(id[static_cast<std::size_t>(t[(k + 1) % 3])]);
      if (a != b) ++uses[std::min(a, b) << 32 | std::max(a, b)];
    }
  detail::UnionFind loops_of(where.size());
  std::vector<bool> on_border(where.size(), false);
  for (const auto& [edge, n] : uses) {
    if (n != 1) continue;
    const int a = static_cast<int>(edge >> 32), b = static_cast<int>(edge & 0xffffffffu);
    on_border[static_cast<std::size_t>(a)] = on_border[static_cast<std::size_t>(b)] = true;
    loops_of.unite(a, b);
  }
  std::unordered_map<int, Eigen::AlignedBox3d> loops;
  for (std::size_t v = 0; v < where.size(); ++v)
    if (on_border[v]) loops[loops_of.find(static_cast<int>(v))].extend(where[v]);
  Holes holes;
  holes.count = static_cast<int>(loops.size());
  for (const auto& [r, box] : loops) holes.widest = std::max(holes.widest, box.diagonal().norm());
  return holes;
}

class AlphaWrapCompleter final : public Completer {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("alpha-wrap")
        .number("relative_alpha", relative_alpha_, Range::above(0), "", "the wrap's alpha, x the part's diagonal")
        .number("relative_offset", relative_offset_, Range::above(0), "", "the wrap's offset, x the part's diagonal")
        .number("max_relative_distance", max_relative_distance_, Range::above(0), "",
                "a part whose surface strays farther from its patch (x the patch's diagonal) fails");
  }

  Result<Completion> complete(const CompletionInput& input) const override {
    return complete_each_part(input, "alpha-wrap", max_relative_distance_,
                              [&](int, const Mesh& patch, CompletedPart& out) { return wrap_part(patch, out); });
  }

 private:
  // Wraps one patch into out.mesh. A wrap that went through a hole of the
  // patch (a thin shell) is kept but rejected.
  Status wrap_part(const Mesh& patch, CompletedPart& out) const {
    const double diag = patch.num_faces() > 0 ? bounds(patch).diagonal().norm() : 0.0;
    if (!(diag > 0) || !std::isfinite(diag))
      return Status::InvalidArgument("alpha-wrap: the part has no faces of positive extent");
    std::vector<Point> points;
    points.reserve(patch.positions.size());
    for (const Eigen::Vector3f& q : patch.positions) points.emplace_back(q.x(), q.y(), q.z());
    std::vector<std::array<std::size_t, 3>> faces;
    faces.reserve(patch.triangles.size());
    for (const Eigen::Vector3i& t : patch.triangles) {
      const std::array<std::size_t, 3> f{static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]),
                                         static_cast<std::size_t>(t[2])};
      // CGAL's oracle skips degenerate triangles, and wrapping nothing crashes: drop them here.
      if (!CGAL::collinear(points[f[0]], points[f[1]], points[f[2]])) faces.push_back(f);
    }
    if (faces.empty())
      return Status::InvalidArgument("alpha-wrap: every triangle of the part is degenerate; nothing to wrap");
    const double alpha = relative_alpha_ * diag, offset = relative_offset_ * diag;
    const auto start = std::chrono::steady_clock::now();
    SurfaceMesh wrap;
    CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);
    if (!CGAL::is_closed(wrap) || wrap.number_of_faces() == 0)
      return Status::Internal("alpha-wrap: CGAL returned an empty or open wrap");
    if (PMP::volume(wrap) < 0) {
      PMP::reverse_face_orientations(wrap);
      out.notes.push_back("alpha-wrap: reversed the wrap's faces to point outward");
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    out.mesh = to_mesh(wrap);
    out.notes.push_back("alpha-wrap: wrapped " + std::to_string(faces.size()) + " triangles with alpha " +
                        number(alpha) + " m and offset " + number(offset) + " m (" + number(relative_alpha_) + " and " +
                        number(relative_offset_) + " of the " + number(diag) + " m diagonal) into " +
                        std::to_string(out.mesh.num_faces()) + " triangles in " + number(seconds) + " s");
    if (const Holes holes = find_holes(patch); holes.count > 0) {
      std::string note = "alpha-wrap: the patch is open (" + std::to_string(holes.count) +
                         " hole(s), the widest spanning " + number(holes.widest / diag) + " of the diagonal)";
      if (alpha < 0.5 * holes.widest)
        // The wrap passes through the hole: a closed but paper-thin shell
        // around the surface whose volume means nothing. Rejected, so
        // complete() falls back to a backend that fills the part.
        return Status::Unavailable(note +
                                   "; alpha is below half of that, so the wrap passes through the hole and is a "
                                   "thin shell around the surface rather than a solid (raise relative_alpha above " +
                                   number(0.5 * holes.widest / diag) +
                                   " to close over it, or use the fill backend); "
                                   "not used");
      out.notes.push_back(note);
    }
    return Status::Ok();
  }

  double relative_alpha_ = 0.01;
  double relative_offset_ = 0.0005;
  double max_relative_distance_ = 0.25;
};

}  // namespace

std::unique_ptr<Completer> make_alpha_wrap_completer() { return std::make_unique<AlphaWrapCompleter>(); }

Status register_cgal_completers() {
  Registry<Completer>& registry = completer_registry();
  const std::pair<const char*, std::unique_ptr<Completer> (*)()> backends[] = {
      {"alpha-wrap", &make_alpha_wrap_completer},
      {"fill", &make_fill_completer},
  };
  for (const auto& [name, factory] : backends) {
    if (registry.contains(name)) continue;
    Status s = registry.add(name, factory);
    if (!s.ok() && !registry.contains(name)) return s;  // a concurrent call may have added it first
  }
  return Status::Ok();
}

}  // namespace g2p
