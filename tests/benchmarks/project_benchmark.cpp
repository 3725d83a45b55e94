// The project stage on a mesh of over a million triangles: SheenChair with
// every triangle split into 4 three times (2.56 M triangles), 11 default views
// at 1024x1024 labelled by the oracle (every pixel of the object votes).
// Single-threaded code; docs/performance.md records the figures:
//
//   build/bin/g2p_project_benchmark --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <unordered_map>

#include "benchmarks/bench_support.h"
#include "g2p/io.h"
#include "g2p/project.h"
#include "g2p/render.h"
#include "g2p/segment.h"

namespace {

struct Fixture {
  g2p::Model model;
  std::vector<g2p::View> views;
  std::vector<g2p::LabelMap> maps;
  g2p::FaceGraph graph;
  g2p::FaceVotes votes;
  double pixels = 0;
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture x;
    const std::string assets = G2P_BENCH_SHARED_ASSETS;
    g2p::ImportOptions io;
    io.load_textures = false;
    x.model = *g2p::load_model(assets + "/SheenChair/SheenChair.glb", io);
    for (int i = 0; i < 3; ++i) x.model.mesh = g2p::bench::subdivide(x.model.mesh);
    g2p::ViewOptions vo;
    vo.width = vo.height = 1024;
    auto renderer = std::move(*g2p::renderer_registry().create("embree"));
    g2p::RenderOptions ids_only;
    ids_only.shade = ids_only.material_buffers = ids_only.geometry_buffers = false;
    (void)renderer->set_model(x.model);
    const std::vector<g2p::Camera> cameras = *g2p::make_views(x.model.mesh, vo);
    for (const g2p::Camera& c : cameras) x.views.push_back(*renderer->render(c, ids_only));
    auto oracle =
        std::move(*g2p::make_segmenter("oracle", {{"labels", assets + "/labels.json"}, {"key", "SheenChair"}}));
    (void)oracle->set_model(x.model, g2p::MaterialTable::paper_default());
    for (const g2p::View& v : x.views) {
      x.maps.push_back(*oracle->segment(v));
      x.maps.back().probabilities = g2p::ImageF();  // hard votes only: free the memory
      x.pixels += static_cast<double>(v.face_id.size());
    }
    x.graph = *g2p::build_face_graph(x.model.mesh);
    x.votes = *g2p::vote(x.model.mesh, x.views, x.maps, 12);
    return x;
  }();
  return f;
}

void BM_Vote(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(g2p::vote(f.model.mesh, f.views, f.maps, 12));
  state.counters["triangles"] = f.model.mesh.num_faces();
  state.counters["Mpixels"] = f.pixels / 1e6;
}

void BM_AssignLabelsWithFloodFill(benchmark::State& state) {
  const Fixture& f = fixture();
  int unseen = 0;
  for (float t : f.votes.total) unseen += t > 0.f ? 0 : 1;
  for (auto _ : state) benchmark::DoNotOptimize(g2p::assign_labels(f.model.mesh, f.graph, f.votes));
  state.counters["unseen_faces"] = unseen;
}

void BM_BuildFaceGraph(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(g2p::build_face_graph(f.model.mesh));
}

void BM_Partition(benchmark::State& state) {
  const Fixture& f = fixture();
  const g2p::FaceLabels labels = g2p::assign_labels(f.model.mesh, f.graph, f.votes);
  std::vector<int> face_part;
  for (auto _ : state) {
    std::vector<int> l = labels.label;
    benchmark::DoNotOptimize(g2p::partition(f.model.mesh, f.graph, l, face_part));
  }
}

BENCHMARK(BM_Vote)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AssignLabelsWithFloodFill)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BuildFaceGraph)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Partition)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
