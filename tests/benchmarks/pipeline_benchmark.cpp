// The whole pipeline with the offline backends (pbr, smooth, partition,
// table) and the paper's 11 views at 512 x 512, on textured shared assets
// split 4-to-1 until they pass a million triangles: SheenChair (40 k
// triangles; x64 = 2.56 M) and GlamVelvetSofa (4.2 k; x256 = 1.07 M). The
// reference in the same run is each asset as it ships (level 0); counters
// give the per-stage split (seconds) and the run's peak resident memory.
// The small case is the bundled hammer (104 triangles), once with the
// pipeline kept between runs (its networks loaded once) and once with a new
// pipeline per run, as each `g2p run` process has (#63).
// docs/performance.md records the figures:
//
//   build/bin/g2p_pipeline_benchmark --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <stdexcept>
#include <string>
#include <utility>

#include "benchmarks/bench_support.h"
#include "g2p/io.h"
#include "g2p/pipeline.h"

namespace {

// The asset with its textures, its mesh split `levels` times. Only the
// current one is kept, so the peak memory counter holds one model.
const g2p::Model& model(const std::string& name, int levels) {
  static std::pair<std::string, int> key;
  static g2p::Model cached;
  if (key == std::make_pair(name, levels) && cached.mesh.num_faces() > 0) return cached;
  cached = g2p::Model{};
  if (name == "hammer") {
    g2p::Result<g2p::Model> m = g2p::load_model(std::string(G2P_BENCH_EXAMPLES) + "/hammer.obj");
    if (!m.ok()) throw std::runtime_error(m.status().to_string());
    cached = std::move(*m);
  } else {
    cached = g2p::bench::load_shared_asset(name);
  }
  for (int l = 0; l < levels; ++l) cached.mesh = g2p::bench::subdivide(cached.mesh);
  key = {name, levels};
  return cached;
}

void run_cases(benchmark::State& state, const std::string& name, int levels, bool fresh) {
  const g2p::Model& m = model(name, levels);
  g2p::Pipeline kept;  // the defaults: 11 views, 512 x 512, offline backends
  g2p::PipelineResult last;
  for (auto _ : state) {
    g2p::Pipeline made;
    g2p::Pipeline& pipeline = fresh ? made : kept;
    g2p::Result<g2p::PipelineResult> r = pipeline.run(m);  // copies the model in, as a loaded file would be
    if (!r.ok()) {
      state.SkipWithError(r.status().to_string().c_str());
      return;
    }
    last = std::move(*r);
  }
  state.counters["triangles"] = m.mesh.num_faces();
  state.counters["parts"] = static_cast<double>(last.projection.parts.size());
  state.counters["peak_MiB"] = static_cast<double>(last.peak_rss_bytes) / (1024.0 * 1024.0);
  for (const g2p::StageReport& s : last.stages) state.counters[std::string(g2p::to_string(s.stage)) + "_s"] = s.seconds;
}

void BM_Pipeline(benchmark::State& state, const std::string& name, int levels) {
  run_cases(state, name, levels, false);
}

// A new pipeline each run: backends made and networks loaded again.
void BM_PipelineFresh(benchmark::State& state, const std::string& name, int levels) {
  run_cases(state, name, levels, true);
}

BENCHMARK_CAPTURE(BM_Pipeline, hammer_104, std::string("hammer"), 0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_PipelineFresh, hammer_104, std::string("hammer"), 0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Pipeline, SheenChair_40k, std::string("SheenChair"), 0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Pipeline, SheenChair_2560k, std::string("SheenChair"), 3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);
BENCHMARK_CAPTURE(BM_Pipeline, GlamVelvetSofa_4k, std::string("GlamVelvetSofa"), 0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Pipeline, GlamVelvetSofa_1070k, std::string("GlamVelvetSofa"), 4)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
