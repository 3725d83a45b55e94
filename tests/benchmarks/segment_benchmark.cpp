// Segmentation time per 512 x 512 view: the `onnx` backend running a network
// (the card named by $G2P_BENCH_MODEL_CARD, e.g. the one tools/training/train.py
// writes; by default the network libg2p ships), the same with test-time mirroring (flip=on) and
// the `learned` backend with the same network,
// against the weight-free `pbr` backend on the same views in the same run.
// SheenChair as shipped, its 11 default views. docs/performance.md and
// docs/training.md record the figures:
//
//   build/bin/g2p_segment_benchmark --benchmark_min_time=2
//   G2P_BENCH_MODEL_CARD=data/model/g2p-materials.json build/bin/g2p_segment_benchmark --benchmark_min_time=2
#include <benchmark/benchmark.h>

#include <cstdlib>

#include "benchmarks/bench_support.h"
#include "g2p/io.h"
#include "g2p/render.h"
#include "g2p/segment.h"

namespace {

struct Scene {
  g2p::Model model;
  std::vector<g2p::View> views;
};

const Scene& scene() {
  static const Scene s = [] {
    Scene sc;
    sc.model = g2p::bench::load_shared_asset("SheenChair");
    auto renderer = g2p::renderer_registry().create("embree");
    sc.views = *g2p::render_views(**renderer, sc.model, *g2p::make_views(sc.model.mesh));
    return sc;
  }();
  return s;
}

void BM_Segment(benchmark::State& state, const std::string& backend, bool needs_card, bool flip = false) {
  g2p::BackendSettings settings;
  if (flip) settings["flip"] = "on";
  if (needs_card) {
    const char* card = std::getenv("G2P_BENCH_MODEL_CARD");
    settings["model_card"] = card != nullptr && *card != '\0' ? card : G2P_BENCH_SHIPPED_CARD;
  }
  const Scene& s = scene();
  auto segmenter = g2p::make_segmenter(backend, settings);
  if (!segmenter.ok() || !(*segmenter)->set_model(s.model, g2p::MaterialTable::paper_default()).ok()) {
    state.SkipWithError(segmenter.ok() ? "set_model failed" : segmenter.status().to_string().c_str());
    return;
  }
  g2p::LabelMap out;
  std::size_t i = 0;
  for (auto _ : state) {
    if (!(*segmenter)->segment_into(s.views[i++ % s.views.size()], out).ok()) {
      state.SkipWithError("segment_into failed");
      return;
    }
  }
  state.counters["views_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_Segment, pbr, std::string("pbr"), false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Segment, onnx, std::string("onnx"), true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Segment, onnx_flip, std::string("onnx"), true, true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Segment, learned, std::string("learned"), true)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
