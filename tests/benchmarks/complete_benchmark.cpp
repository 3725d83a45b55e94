// The complete stage against object size and grid resolution: SheenChair
// (40 k triangles) split 4-to-1 up to three times (2.56 M), one part per
// source material. The reference in the same run is CGAL's alpha wrapping of
// the same parts (the optional g2p::cgal component, when built), the approach
// the partition completer replaces. BM_ClosedPartSurface times the check that
// keeps a part already closed. docs/performance.md records the figures:
//
//   build/bin/g2p_complete_benchmark --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <algorithm>

#include "benchmarks/bench_support.h"
#include "g2p/complete.h"
#include "g2p/io.h"
#ifdef G2P_BENCH_WITH_CGAL
#include "g2p/complete_cgal.h"
#endif

namespace {

struct Object {
  g2p::Mesh mesh;
  std::vector<g2p::Part> parts;
};

// Level 0..3 of subdivision, built once each.
const Object& object(int level) {
  static std::vector<Object> cache = [] {
    std::vector<Object> levels(4);
    g2p::ImportOptions io;
    io.load_textures = false;
    g2p::Model model = g2p::bench::load_shared_asset("SheenChair", io);
    for (int l = 0; l < 4; ++l) {
      if (l > 0) model.mesh = g2p::bench::subdivide(model.mesh);
      Object& o = levels[static_cast<std::size_t>(l)];
      o.mesh = model.mesh;
      o.parts.resize(model.materials.size());
      for (int f = 0; f < o.mesh.num_faces(); ++f) {
        g2p::Part& p = o.parts[static_cast<std::size_t>(o.mesh.face_source[static_cast<std::size_t>(f)].material)];
        p.faces.push_back(f);
        p.area_m2 += g2p::face_area(o.mesh, f);
      }
      o.parts.erase(std::remove_if(o.parts.begin(), o.parts.end(), [](const g2p::Part& p) { return p.faces.empty(); }),
                    o.parts.end());
      for (std::size_t p = 0; p < o.parts.size(); ++p) o.parts[p].label = static_cast<int>(p);
    }
    return levels;
  }();
  return cache[static_cast<std::size_t>(level)];
}

void run(benchmark::State& state, const std::string& backend, const g2p::BackendSettings& settings, int level) {
  const Object& o = object(level);
  auto completer = g2p::make_completer(backend, settings);
  if (!completer.ok()) {
    state.SkipWithError(completer.status().to_string().c_str());
    return;
  }
  g2p::Completion last;
  for (auto _ : state) {
    auto r = (*completer)->complete({&o.mesh, &o.parts, nullptr});
    if (!r.ok()) {
      state.SkipWithError(r.status().to_string().c_str());
      return;
    }
    last = std::move(*r);
  }
  int ok = 0;
  double triangles = 0;
  for (const auto& p : last.parts) ok += p.ok, triangles += p.mesh.num_faces();
  state.counters["input_triangles"] = o.mesh.num_faces();
  state.counters["parts_ok"] = ok;
  state.counters["parts"] = static_cast<double>(last.parts.size());
  state.counters["output_triangles"] = triangles;
  state.counters["volume_cm3"] = last.parts_volume_m3 * 1e6;
}

// Partition at the default resolution (160) against input size.
void BM_PartitionBySize(benchmark::State& state) { run(state, "partition", {}, static_cast<int>(state.range(0))); }
BENCHMARK(BM_PartitionBySize)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

// Partition on the 160 k-triangle chair against grid resolution.
void BM_PartitionByResolution(benchmark::State& state) {
  const std::string r = std::to_string(state.range(0));
  run(state, "partition", {{"resolution", r}, {"max_resolution", r}}, 1);
}
BENCHMARK(BM_PartitionByResolution)
    ->Arg(64)
    ->Arg(128)
    ->Arg(160)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Partition without the simplification pass (the marching-tetrahedra surface as is).
void BM_PartitionNoSimplify(benchmark::State& state) { run(state, "partition", {{"simplify", "0"}}, 1); }
BENCHMARK(BM_PartitionNoSimplify)->Unit(benchmark::kMillisecond)->UseRealTime();

// Is a part already a solid? closed_part_surface (welding, the closed,
// manifold and orientation checks, the self-intersection search) on a
// sphere of 524,288 triangles, an octahedron split 4-to-1 eight times with
// every vertex pushed onto the sphere: the check every kept part of a
// million-triangle mesh goes through.
void BM_ClosedPartSurface(benchmark::State& state) {
  static const g2p::Mesh sphere = [] {
    g2p::Mesh m;
    m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    for (int level = 0; level < 8; ++level) {
      m = g2p::bench::subdivide(m);
      for (auto& p : m.positions) p = 0.3f * p.normalized();
    }
    return m;
  }();
  g2p::Part part;
  part.label = 0;
  for (int f = 0; f < sphere.num_faces(); ++f) part.faces.push_back(f);
  int kept = 0;
  for (auto _ : state) kept = g2p::closed_part_surface(sphere, part).num_faces();
  state.counters["triangles"] = sphere.num_faces();
  state.counters["kept_triangles"] = kept;
}
BENCHMARK(BM_ClosedPartSurface)->Unit(benchmark::kMillisecond)->UseRealTime();

#ifdef G2P_BENCH_WITH_CGAL
// Reference: CGAL alpha wrapping part by part, on the base chair only.
void BM_AlphaWrapReference(benchmark::State& state) {
  (void)g2p::register_cgal_completers();
  run(state, "alpha-wrap", {}, 0);
}
BENCHMARK(BM_AlphaWrapReference)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
#endif

}  // namespace

BENCHMARK_MAIN();
