// Benchmarks of the identify stage's own geometry: shape_cues() (the kind
// classifier's shape head reads them on every run) on a real chair and on
// that chair subdivided to about a million triangles, beside a reference
// pass that only sums the same triangles' areas (docs/performance.md).
#include <benchmark/benchmark.h>

#include <map>

#include "benchmarks/bench_support.h"
#include "g2p/identify.h"

namespace {

const g2p::Mesh& chair(int subdivisions) {
  static std::map<int, g2p::Mesh> meshes;
  auto it = meshes.find(subdivisions);
  if (it != meshes.end()) return it->second;
  g2p::Mesh m = g2p::bench::load_shared_asset("SheenChair").mesh;
  for (int i = 0; i < subdivisions; ++i) m = g2p::bench::subdivide(m);
  return meshes.emplace(subdivisions, std::move(m)).first->second;
}

void BM_ShapeCues(benchmark::State& state) {
  const g2p::Mesh& m = chair(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(g2p::shape_cues(m));
  state.counters["triangles"] = m.num_faces();
}

// Reference: one pass over the triangles summing their areas.
void BM_AreaReference(benchmark::State& state) {
  const g2p::Mesh& m = chair(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    double area = 0;
    for (const Eigen::Vector3i& t : m.triangles)
      area += 0.5 * (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]).norm();
    benchmark::DoNotOptimize(area);
  }
  state.counters["triangles"] = m.num_faces();
}

}  // namespace

BENCHMARK(BM_ShapeCues)->Arg(0)->Arg(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AreaReference)->Arg(0)->Arg(3)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
