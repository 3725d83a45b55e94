// Import speed on the shared assets, against a reference measured in the same
// run: assimp's own ReadFile of the same file (what any assimp-based importer
// pays at least); and PNG writing against a raw write of the same pixels.
// docs/performance.md records the figures and the command.
//
//   build/bin/g2p_import_benchmark --benchmark_min_time=1
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <benchmark/benchmark.h>
#include <assimp/Importer.hpp>

#include <unistd.h>

#include <filesystem>
#include <map>
#include <string>

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

// Writing a PNG (write_image: libpng at level 1, Z_RLE, the Paeth filter) of
// each asset's first base colour texture, RGBA, against writing the same pixels
// raw (write_text_file), the reference.
const g2p::ImageU8& texture(int i) {
  static std::map<int, g2p::ImageU8> images;
  if (!images.count(i)) {
    g2p::Result<g2p::Model> m = g2p::load_model(asset(i));
    g2p::ImageU8 image;
    if (m.ok())
      for (const g2p::SourceMaterial& mat : m->materials)
        if (!mat.base_color_texture.empty()) {
          image = *mat.base_color_texture.image;
          break;
        }
    images[i] = std::move(image);
  }
  return images[i];
}

void BM_WritePng(benchmark::State& state) {
  const g2p::ImageU8& image = texture(static_cast<int>(state.range(0)));
  if (image.empty()) state.SkipWithError("no base colour texture");
  const std::string path = "/tmp/g2p_bench_" + std::to_string(::getpid()) + ".png";
  for (auto _ : state)
    if (!g2p::write_image(path, image).ok()) state.SkipWithError("write_image failed");
  state.counters["bytes"] = static_cast<double>(std::filesystem::file_size(path));
  std::filesystem::remove(path);
  state.SetLabel(std::string(kAssets[state.range(0)]) + " " + std::to_string(image.width()) + "x" +
                 std::to_string(image.height()));
}

void BM_WriteRawReference(benchmark::State& state) {
  const g2p::ImageU8& image = texture(static_cast<int>(state.range(0)));
  const std::string pixels(reinterpret_cast<const char*>(image.data()),
                           static_cast<std::size_t>(image.width()) * image.height() * image.channels());
  const std::string path = "/tmp/g2p_bench_" + std::to_string(::getpid()) + ".raw";
  for (auto _ : state)
    if (!g2p::write_text_file(path, pixels).ok()) state.SkipWithError("write failed");
  std::filesystem::remove(path);
  state.SetLabel(kAssets[state.range(0)]);
}

BENCHMARK(BM_WritePng)->Arg(0)->Arg(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WriteRawReference)->Arg(0)->Arg(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AssimpReadFile)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoadModel)->ArgsProduct({{0, 1, 2, 3, 4}, {0, 1}, {1, 0}})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
