// The Decomposer base class, the registry, and decompose_part(): the
// backend's result checked, replaced by the single hull when it fails, and
// measured the same way for every backend.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>

#include "decompose/backends.h"
#include "decompose/coverage.h"
#include "decompose/voxel_grid.h"

namespace g2p {

Decomposer::~Decomposer() = default;

SettingsSpec Decomposer::settings() { return SettingsSpec("this decomposer"); }

Status Decomposer::configure(const BackendSettings& settings) { return this->settings().apply(settings); }

Registry<Decomposer>& decomposer_registry() {
  static Registry<Decomposer>* registry = [] {
    auto* r = new Registry<Decomposer>("decomposer");  // never destroyed: usable during static destruction
    (void)r->add("voxel-cut", &make_voxel_cut_decomposer);
    (void)r->add("hull", &make_hull_decomposer);
#ifdef G2P_WITH_HACD
    (void)r->add("hacd", &make_hacd_decomposer);
#endif
    return r;
  }();
  return *registry;
}

Status validate(const DecomposeOptions& o) {
  if (o.max_hulls < 1 || o.max_hulls > 256)
    return Status::InvalidArgument("--max-hulls must be 1..256 (got " + std::to_string(o.max_hulls) + ")");
  if (o.max_vertices_per_hull < 4 || o.max_vertices_per_hull > 255)
    return Status::InvalidArgument("--hull-vertices must be 4..255 (got " + std::to_string(o.max_vertices_per_hull) +
                                   ")");
  if (!(o.min_depth_m >= 0) || !std::isfinite(o.min_depth_m))
    return Status::InvalidArgument("--min-concavity must be a length of 0 m or more");
  if (o.measure_resolution < 16 || o.measure_resolution > 512)
    return Status::InvalidArgument("the measuring grid's resolution must be 16..512 cells (got " +
                                   std::to_string(o.measure_resolution) + ")");
  if (!(o.coverage_tolerance >= 0 && o.coverage_tolerance <= 1))
    return Status::InvalidArgument("--coverage-tolerance must be a share of the object's diagonal, 0..1");
  if (o.max_hulls_per_object < 0 || o.max_hulls_per_object > 65536)
    return Status::InvalidArgument("--max-hulls-per-object must be 0..65536 (got " +
                                   std::to_string(o.max_hulls_per_object) + ")");
  return Status::Ok();
}

double enclosed_volume(const Mesh& mesh) {
  double six_v = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = mesh.positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = mesh.positions[static_cast<std::size_t>(t[2])].cast<double>();
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

namespace {

// A hull is usable by an engine: at least a tetrahedron, within the vertex
// budget, finite, enclosing a positive volume.
std::string hull_problem(const Mesh& hull, const DecomposeOptions& options) {
  if (hull.num_vertices() < 4 || hull.num_faces() < 4) return "a hull with fewer than 4 vertices";
  if (hull.num_vertices() > options.max_vertices_per_hull)
    return "a hull of " + std::to_string(hull.num_vertices()) + " vertices (budget " +
           std::to_string(options.max_vertices_per_hull) + ")";
  if (!validate(hull).ok()) return "an invalid hull mesh";
  if (!(enclosed_volume(hull) > 0)) return "a hull without volume";
  return {};
}

// Single hull of the part's vertices; a flat part is given a thickness of
// 1 % of its size (at least 1 mm) so that it still collides.
Status single_hull(const Mesh& closed, const DecomposeOptions& options, ConvexDecomposition& out) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(closed.positions.size());
  for (const Eigen::Vector3f& p : closed.positions) points.push_back(p.cast<double>());
  Result<Mesh> hull = convex_hull(points, options.max_vertices_per_hull);
  if (!hull.ok() && points.size() >= 3) {
    const Eigen::AlignedBox3d box = bounds(closed);
    int axis = 0;
    box.sizes().minCoeff(&axis);
    const double half = 0.5 * std::max(1e-3, 0.01 * box.sizes().maxCoeff());
    const std::size_t n = points.size();
    for (std::size_t i = 0; i < n; ++i) {
      Eigen::Vector3d q = points[i];
      q[axis] += half;
      points.push_back(q);
      points[i][axis] -= half;
    }
    hull = convex_hull(points, options.max_vertices_per_hull);
    if (hull.ok())
      out.notes.push_back("the part is flat; its hull was given " + std::to_string(2 * half) + " m of thickness");
  }
  if (!hull.ok())
    return Status::InvalidArgument("no convex hull: the part has fewer than 4 points off one line (" +
                                   hull.status().message() + ")");
  out.hulls = {std::move(*hull)};
  return Status::Ok();
}

// Mean and largest distance from hull-surface samples to the part's voxels.
void measure(const Mesh& closed, const DecomposeOptions& options, ConvexDecomposition& out) {
  const detail::VoxelGrid grid = detail::voxelize(closed, options.measure_resolution, 2);
  if (grid.occupied.empty()) return;
  const std::vector<float> distance = detail::distance_to_occupied(grid);
  double area = 0.0;
  for (const Mesh& h : out.hulls) area += surface_area(h);
  if (!(area > 0)) return;
  const double per_m2 = 20000.0 / area;  // about 20k samples over all hulls
  double sum = 0.0, largest = 0.0;
  long samples = 0;
  auto distance_at = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d q = (p - grid.origin) / grid.cell_m;
    Eigen::Vector3i c;
    double outside = 0.0;  // beyond the grid: add the way to its border
    for (int a = 0; a < 3; ++a) {
      const double f = std::floor(q[a]);
      c[a] = static_cast<int>(std::clamp(f, 0.0, grid.size[a] - 1.0));
      if (q[a] < 0) outside = std::max(outside, -q[a] * grid.cell_m);
      if (q[a] > grid.size[a]) outside = std::max(outside, (q[a] - grid.size[a]) * grid.cell_m);
    }
    return distance[grid.index(c.x(), c.y(), c.z())] + outside;
  };
  for (const Mesh& h : out.hulls)
    for (int f = 0; f < h.num_faces(); ++f) {
      const Eigen::Vector3i& t = h.triangles[static_cast<std::size_t>(f)];
      const Eigen::Vector3d a = h.positions[static_cast<std::size_t>(t[0])].cast<double>();
      const Eigen::Vector3d b = h.positions[static_cast<std::size_t>(t[1])].cast<double>();
      const Eigen::Vector3d c = h.positions[static_cast<std::size_t>(t[2])].cast<double>();
      // A regular pattern of barycentric samples, denser on larger faces.
      const int n = std::max(1, static_cast<int>(std::ceil(std::sqrt(face_area(h, f) * per_m2))));
      for (int u = 0; u < n; ++u)
        for (int v = 0; u + v < n; ++v) {
          const double s = (u + 1.0 / 3.0) / n, r = (v + 1.0 / 3.0) / n;
          const double d = distance_at(a + s * (b - a) + r * (c - a));
          sum += d;
          largest = std::max(largest, d);
          ++samples;
        }
    }
  if (samples > 0) out.mean_distance_m = sum / samples;
  out.max_distance_m = largest;
}

}  // namespace

Result<ConvexDecomposition> decompose_part(const Mesh& closed, const Decomposer& decomposer,
                                           const DecomposeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  G2P_RETURN_IF_ERROR(validate(options));
  G2P_RETURN_IF_ERROR(validate(closed).with_context("decompose"));
  if (closed.num_faces() == 0) return Status::InvalidArgument("decompose: the part's closed volume is empty");
  ConvexDecomposition out;
  std::string problem;
  try {
    Status s = decomposer.decompose(closed, options, out);
    if (!s.ok()) problem = s.message();
  } catch (const std::exception& e) {
    problem = std::string("the backend threw: ") + e.what();
  }
  if (problem.empty() && out.hulls.empty()) problem = "the backend returned no hull";
  if (problem.empty() && static_cast<int>(out.hulls.size()) > options.max_hulls)
    problem = "the backend returned " + std::to_string(out.hulls.size()) + " hulls (budget " +
              std::to_string(options.max_hulls) + ")";
  for (std::size_t i = 0; problem.empty() && i < out.hulls.size(); ++i) {
    const std::string p = hull_problem(out.hulls[i], options);
    if (!p.empty()) problem = "hull " + std::to_string(i) + ": " + p;
  }
  if (!problem.empty()) {
    std::vector<std::string> notes = std::move(out.notes);
    out = ConvexDecomposition{};
    out.notes = std::move(notes);
    out.notes.push_back("decomposition failed (" + problem + "); the part collides as its single convex hull");
    out.fell_back = true;
    out.backend = "hull";
    G2P_RETURN_IF_ERROR(single_hull(closed, options, out).with_context("decompose"));
  }
  out.part_volume_m3 = enclosed_volume(closed);
  for (const Mesh& h : out.hulls) out.hulls_volume_m3 += enclosed_volume(h);
  measure(closed, options, out);
  const detail::Uncovered uncovered = detail::uncovered_distance(closed, out.hulls);
  out.uncovered_mean_m = uncovered.mean_m;
  out.uncovered_max_m = uncovered.max_m;
  out.hull_budget = options.max_hulls;
  out.coverage_tolerance_m = options.coverage_tolerance * bounds(closed).diagonal().norm();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

namespace {

// Part i of the completion, as decompose_parts() describes.
// `object_diagonal`: the length of `object`'s bounding-box diagonal (0 without one).
ConvexDecomposition decompose_one(const Completion& completion, const Decomposer& decomposer,
                                  const DecomposeOptions& options, const std::string& backend, const Mesh* object,
                                  double object_diagonal, const std::vector<Part>* parts, std::size_t i) {
  ConvexDecomposition out;
  const Mesh& closed = completion.parts[i].mesh;
  if (closed.num_faces() == 0) {
    out.notes.push_back("no closed volume to decompose");
    return out;
  }
  DecomposeOptions own = options;
  if (object != nullptr && own.min_depth_m == 0) own.min_depth_m = 0.01 * object_diagonal;
  if (object != nullptr && parts != nullptr && i < parts->size()) {
    // The part's distinct vertex positions: those of its vertices, sorted.
    std::vector<char> used(object->positions.size(), 0);
    std::vector<std::array<float, 3>> corners;
    for (int f : (*parts)[i].faces)
      for (int k = 0; k < 3; ++k) {
        const auto v = static_cast<std::size_t>(object->triangles[static_cast<std::size_t>(f)][k]);
        if (used[v]) continue;
        used[v] = 1;
        const Eigen::Vector3f& p = object->positions[v];
        corners.push_back({p.x(), p.y(), p.z()});
      }
    std::sort(corners.begin(), corners.end());
    const auto distinct = std::unique(corners.begin(), corners.end()) - corners.begin();
    own.max_vertices_per_hull = std::clamp(static_cast<int>(distinct), 4, options.max_vertices_per_hull);
  }
  Result<ConvexDecomposition> d = decompose_part(closed, decomposer, own);
  if (!d.ok()) {
    out.notes.push_back(d.status().message());
    return out;
  }
  out = std::move(*d);
  if (out.backend.empty()) out.backend = backend;
  if (object != nullptr) out.coverage_tolerance_m = options.coverage_tolerance * object_diagonal;
  return out;
}

// The larger of the two distances decompose_parts() holds to the tolerance.
double worst_distance(const ConvexDecomposition& d) { return std::max(d.max_distance_m, d.uncovered_max_m); }

bool misses(const ConvexDecomposition& d) { return !d.hulls.empty() && worst_distance(d) > d.coverage_tolerance_m; }

std::string millimetres(double m) {
  std::ostringstream s;
  s.precision(3);
  s << 1000.0 * m << " mm";
  return s.str();
}

std::string distances(const ConvexDecomposition& d) {
  return "hulls stand up to " + millimetres(d.max_distance_m) + " outside the part and leave up to " +
         millimetres(d.uncovered_max_m) + " of its surface uncovered";
}

}  // namespace

std::vector<ConvexDecomposition> decompose_parts(const Completion& completion, const Decomposer& decomposer,
                                                 const DecomposeOptions& options, const std::string& backend,
                                                 const Mesh* object, const std::vector<Part>* parts,
                                                 const StageProgress& progress) {
  std::vector<ConvexDecomposition> out(completion.parts.size());
  const double object_diagonal = object != nullptr ? bounds(*object).diagonal().norm() : 0.0;  // once, not per part
  std::mutex reporting;
  std::size_t finished = 0;
  Status stop;  // the first error progress returned; guarded by `reporting`
  std::atomic<bool> stopped{false};
  tbb::parallel_for(std::size_t{0}, out.size(), [&](std::size_t i) {
    if (stopped) {
      std::lock_guard<std::mutex> lock(reporting);
      out[i].backend = backend;
      out[i].notes.push_back("not decomposed: " + stop.message());
      return;
    }
    out[i] = decompose_one(completion, decomposer, options, backend, object, object_diagonal, parts, i);
    if (!progress) return;
    std::lock_guard<std::mutex> lock(reporting);
    ++finished;
    if (!stop.ok()) return;
    stop = progress(static_cast<double>(finished) / static_cast<double>(out.size()),
                    "part " + std::to_string(i) + ": " + std::to_string(out[i].hulls.size()) + " hulls");
    if (!stop.ok()) stopped = true;
  });
  if (stopped) return out;

  // Coverage: parts that spent their whole budget and still miss the
  // tolerance are decomposed again with twice the budget, the worst first,
  // while the object's hulls stay within max_hulls_per_object.
  constexpr int kMostHullsPerPart = 256;  // validate()'s bound on max_hulls
  long total = 0;
  for (const ConvexDecomposition& d : out) total += static_cast<long>(d.hulls.size());
  std::vector<int> first_budget(out.size());
  for (std::size_t i = 0; i < out.size(); ++i) first_budget[i] = out[i].hull_budget;
  std::vector<bool> settled(out.size(), false);  // raising did not help, or cannot
  for (;;) {
    std::vector<std::size_t> candidates;
    for (std::size_t i = 0; i < out.size(); ++i)
      if (!settled[i] && !out[i].fell_back && misses(out[i]) &&
          static_cast<int>(out[i].hulls.size()) >= out[i].hull_budget && out[i].hull_budget < kMostHullsPerPart)
        candidates.push_back(i);
    std::sort(candidates.begin(), candidates.end(),
              [&](std::size_t a, std::size_t b) { return worst_distance(out[a]) > worst_distance(out[b]); });
    std::vector<std::pair<std::size_t, int>> round;  // part, its raised budget
    long room = options.max_hulls_per_object - total;
    for (std::size_t i : candidates) {
      const int used = static_cast<int>(out[i].hulls.size());
      const int budget = static_cast<int>(
          std::min<long>({2L * out[i].hull_budget, kMostHullsPerPart, static_cast<long>(used) + room}));
      if (budget <= used) continue;
      room -= budget - used;
      round.emplace_back(i, budget);
    }
    if (round.empty()) break;
    if (progress) {  // a cancelled run stops raising; the hulls so far stand
      std::lock_guard<std::mutex> lock(reporting);
      if (!progress(1.0,
                    "raising the hull budget of " + std::to_string(round.size()) + " parts for --coverage-tolerance")
               .ok())
        break;
    }
    std::vector<ConvexDecomposition> again(round.size());
    tbb::parallel_for(std::size_t{0}, round.size(), [&](std::size_t r) {
      DecomposeOptions raised = options;
      raised.max_hulls = round[r].second;
      again[r] = decompose_one(completion, decomposer, raised, backend, object, object_diagonal, parts, round[r].first);
    });
    for (std::size_t r = 0; r < round.size(); ++r) {
      const std::size_t i = round[r].first;
      ConvexDecomposition& d = again[r];
      // The largest distance need not fall with every doubling (one gap of
      // several still bridged keeps it), so an equal one that spent its
      // whole budget is kept and raised again; a worse one, or an equal one
      // the backend finished within budget (more hulls for nothing), ends
      // the raise with the result before it.
      const bool better = worst_distance(d) < worst_distance(out[i]);
      const bool progressing =
          worst_distance(d) == worst_distance(out[i]) && static_cast<int>(d.hulls.size()) >= d.hull_budget;
      if (d.hulls.empty() || d.fell_back || !(better || progressing)) {
        settled[i] = true;
        out[i].seconds += d.seconds;  // the attempt counts in the part's time
        continue;
      }
      d.seconds += out[i].seconds;
      total += static_cast<long>(d.hulls.size()) - static_cast<long>(out[i].hulls.size());
      out[i] = std::move(d);
    }
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    ConvexDecomposition& d = out[i];
    if (d.hull_budget > first_budget[i])
      d.notes.push_back("hull budget raised from " + std::to_string(first_budget[i]) + " to " +
                        std::to_string(d.hull_budget) + " to bring the hulls within " +
                        millimetres(d.coverage_tolerance_m) + " of the part (--coverage-tolerance)");
    if (!misses(d)) continue;
    std::string why;
    if (static_cast<int>(d.hulls.size()) < d.hull_budget)
      why = "the backend needed no more hulls (its own tolerance, or the part's fine detail)";
    else if (d.fell_back)
      why = "the part fell back to its single hull";
    else if (settled[i])
      why = "more hulls brought them no closer";
    else if (d.hull_budget >= kMostHullsPerPart)
      why = "the part's budget reached " + std::to_string(kMostHullsPerPart) + " hulls";
    else
      why = "the object's limit of " + std::to_string(options.max_hulls_per_object) +
            " hulls is reached (--max-hulls-per-object)";
    d.notes.push_back("coverage: " + distances(d) + ", beyond the tolerance of " + millimetres(d.coverage_tolerance_m) +
                      " with " + std::to_string(d.hulls.size()) + " hulls: " + why);
  }
  return out;
}

}  // namespace g2p
