// The decompose stage on the closed parts of shared assets: `voxel-cut`
// (the default) and `hacd` (when built with it) against `hull` (one convex hull per part, what an engine
// does with a raw mesh: the reference of the same run). Each asset runs
// through the pipeline up to the properties stage once (default options:
// 11 views, pbr, smooth, partition, table); the benchmark then decomposes
// all its parts with the pipeline's per-part budgets (raised where a part
// misses --coverage-tolerance). Counters: parts, hulls, the largest distance
// from a hull to its part and the largest of its surface left uncovered. docs/performance.md
// records the figures:
//
//   build/bin/g2p_decompose_benchmark --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <map>
#include <string>

#include "benchmarks/bench_support.h"
#include "g2p/decompose.h"
#include "g2p/pipeline.h"

namespace {

const g2p::PipelineResult& completed(const std::string& name) {
  static std::map<std::string, g2p::PipelineResult> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  g2p::PipelineOptions options;
  options.last_stage = g2p::Stage::kProperties;
  g2p::Pipeline pipeline(options);
  g2p::Result<g2p::PipelineResult> r = pipeline.run(g2p::bench::load_shared_asset(name));
  if (!r.ok()) throw std::runtime_error(r.status().to_string());
  return cache.emplace(name, std::move(*r)).first->second;
}

void BM_Decompose(benchmark::State& state, const std::string& name, const std::string& backend) {
  if (!g2p::decomposer_registry().contains(backend)) {
    state.SkipWithError(("no backend " + backend + " in this build").c_str());
    return;
  }
  const g2p::PipelineResult& r = completed(name);
  std::unique_ptr<g2p::Decomposer> decomposer = std::move(*g2p::make_decomposer(backend));
  std::vector<g2p::ConvexDecomposition> out;
  for (auto _ : state)
    out = g2p::decompose_parts(r.completion, *decomposer, {}, backend, &r.model.mesh, &r.projection.parts);
  double hulls = 0, farthest = 0, uncovered = 0;
  for (const g2p::ConvexDecomposition& d : out) {
    hulls += static_cast<double>(d.hulls.size());
    farthest = std::max(farthest, d.max_distance_m);
    uncovered = std::max(uncovered, d.uncovered_max_m);
  }
  state.counters["parts"] = static_cast<double>(out.size());
  state.counters["hulls"] = hulls;
  state.counters["max_distance_mm"] = 1000.0 * farthest;
  state.counters["uncovered_max_mm"] = 1000.0 * uncovered;
}

#define G2P_DECOMPOSE_CASE(asset)                                                                   \
  BENCHMARK_CAPTURE(BM_Decompose, asset##_hull, std::string(#asset), std::string("hull"))           \
      ->Unit(benchmark::kMillisecond)                                                               \
      ->UseRealTime();                                                                              \
  BENCHMARK_CAPTURE(BM_Decompose, asset##_voxel_cut, std::string(#asset), std::string("voxel-cut")) \
      ->Unit(benchmark::kMillisecond)                                                               \
      ->UseRealTime();                                                                              \
  BENCHMARK_CAPTURE(BM_Decompose, asset##_hacd, std::string(#asset), std::string("hacd"))           \
      ->Unit(benchmark::kMillisecond)                                                               \
      ->UseRealTime();

G2P_DECOMPOSE_CASE(SheenChair)
G2P_DECOMPOSE_CASE(GlamVelvetSofa)
G2P_DECOMPOSE_CASE(GlassHurricaneCandleHolder)
G2P_DECOMPOSE_CASE(WaterBottle)
G2P_DECOMPOSE_CASE(Avocado)

}  // namespace

BENCHMARK_MAIN();
