// Import speed on the shared assets, against a reference measured in the same
// run: assimp's own ReadFile of the same file (what any assimp-based importer
// pays at least). docs/performance.md records the figures and the command.
//
//   build/bin/g2p_import_benchmark --benchmark_min_time=1
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <benchmark/benchmark.h>
#include <assimp/Importer.hpp>

#include "g2p/io.h"

namespace {

const char* const kAssets[] = {"Avocado", "GlamVelvetSofa", "GlassHurricaneCandleHolder", "SheenChair", "WaterBottle"};

std::string asset(int i) { return std::string(G2P_BENCH_SHARED_ASSETS) + "/" + kAssets[i] + "/" + kAssets[i] + ".glb"; }

// Reference: assimp parsing alone, with the post-processing libg2p asks for.
void BM_AssimpReadFile(benchmark::State& state) {
  const std::string path = asset(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(path, aiProcess_JoinIdenticalVertices);
    if (scene == nullptr) state.SkipWithError(importer.GetErrorString());
    benchmark::DoNotOptimize(scene);
  }
  state.SetLabel(kAssets[state.range(0)]);
}

void BM_LoadModel(benchmark::State& state) {
  const std::string path = asset(static_cast<int>(state.range(0)));
  g2p::ImportOptions options;
  options.load_textures = state.range(1) != 0;
  options.isolate_reader = state.range(2) != 0;  // assimp in a child process (the default)
  for (auto _ : state) {
    g2p::Result<g2p::Model> model = g2p::load_model(path, options);
    if (!model.ok()) state.SkipWithError(model.status().message().c_str());
    benchmark::DoNotOptimize(model);
  }
  state.SetLabel(std::string(kAssets[state.range(0)]) + (options.load_textures ? " +textures" : "") +
                 (options.isolate_reader ? " child" : " in-process"));
}

BENCHMARK(BM_AssimpReadFile)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoadModel)->ArgsProduct({{0, 1, 2, 3, 4}, {0, 1}, {1, 0}})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
