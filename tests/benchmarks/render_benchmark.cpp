// Render throughput on a mesh of over a million triangles (SheenChair, each
// triangle split into 4 three times: 2.56 M triangles), 11 default views at
// 512x512, against a bare Embree primary-ray loop on the same scene and
// cameras in the same run (one rtcIntersect1 per pixel, TBB tiles, no shading).
// The passes reuse one View; BM_RenderViews renders into fresh Views, as the
// pipeline's render stage and `g2p render` do, also at 1024 x 1024 (#63: at
// most 2.5 times the bare loop at the same size).
// docs/performance.md records the figures and the command:
//
//   build/bin/g2p_render_benchmark --benchmark_min_time=2
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <map>
#include <memory>
#include <unordered_map>

#include "benchmarks/bench_support.h"
#include "g2p/io.h"
#include "g2p/render.h"

namespace {

struct Scene {
  g2p::Model model;
  std::vector<g2p::Camera> cameras;
  double rays = 0;  // primary rays per pass over all cameras
};

const Scene& scene() {
  static const Scene s = [] {
    Scene sc;
    sc.model = g2p::bench::load_shared_asset("SheenChair");
    for (int i = 0; i < 3; ++i) sc.model.mesh = g2p::bench::subdivide(sc.model.mesh);
    sc.cameras = *g2p::make_views(sc.model.mesh);
    for (const g2p::Camera& c : sc.cameras) sc.rays += static_cast<double>(c.width) * c.height;
    return sc;
  }();
  return s;
}

// The scene's cameras at `side` x `side` pixels.
const std::vector<g2p::Camera>& cameras(int side) {
  static std::map<int, std::vector<g2p::Camera>> by_side;
  auto it = by_side.find(side);
  if (it == by_side.end()) {
    g2p::ViewOptions o;
    o.width = o.height = side;
    it = by_side.emplace(side, *g2p::make_views(scene().model.mesh, o)).first;
  }
  return it->second;
}

double rays(int side) { return static_cast<double>(cameras(side).size()) * side * side; }

void report(benchmark::State& state, int side = 512) {
  state.counters["Mrays/s"] =
      benchmark::Counter(rays(side) * static_cast<double>(state.iterations()) / 1e6, benchmark::Counter::kIsRate);
  state.counters["triangles"] = static_cast<double>(scene().model.mesh.num_faces());
}

// The reference: Embree alone, same geometry, scene flags, tiles and rays.
void BM_BareEmbreeLoop(benchmark::State& state) {
  const Scene& s = scene();
  const int side = static_cast<int>(state.range(0));
  RTCDevice device = rtcNewDevice(nullptr);
  RTCScene rtc = rtcNewScene(device);
  rtcSetSceneFlags(rtc, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), s.model.mesh.positions.size()));
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), s.model.mesh.triangles.size()));
  for (std::size_t i = 0; i < s.model.mesh.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + k] = s.model.mesh.positions[i][k];
  for (std::size_t i = 0; i < s.model.mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) idx[3 * i + k] = static_cast<unsigned>(s.model.mesh.triangles[i][k]);
  rtcCommitGeometry(g);
  rtcAttachGeometry(rtc, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(rtc);

  std::vector<int> ids;
  for (auto _ : state) {
    for (const g2p::Camera& cam : cameras(side)) {
      ids.assign(static_cast<std::size_t>(cam.width) * cam.height, -1);
      tbb::parallel_for(tbb::blocked_range2d<int>(0, cam.height, 32, 0, cam.width, 32),
                        [&](const tbb::blocked_range2d<int>& r) {
                          RTCIntersectContext ctx;
                          rtcInitIntersectContext(&ctx);
                          ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
                          for (int y = r.rows().begin(); y != r.rows().end(); ++y) {
                            for (int x = r.cols().begin(); x != r.cols().end(); ++x) {
                              Eigen::Vector3d o, d;
                              cam.ray(x + 0.5, y + 0.5, o, d);
                              alignas(16) RTCRayHit rh{};
                              rh.ray.org_x = static_cast<float>(o.x());
                              rh.ray.org_y = static_cast<float>(o.y());
                              rh.ray.org_z = static_cast<float>(o.z());
                              rh.ray.dir_x = static_cast<float>(d.x());
                              rh.ray.dir_y = static_cast<float>(d.y());
                              rh.ray.dir_z = static_cast<float>(d.z());
                              rh.ray.tfar = std::numeric_limits<float>::infinity();
                              rh.ray.mask = 0xFFFFFFFFu;
                              rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                              rtcIntersect1(rtc, &ctx, &rh);
                              ids[static_cast<std::size_t>(y) * cam.width + x] =
                                  rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? -1 : static_cast<int>(rh.hit.primID);
                            }
                          }
                        });
      benchmark::DoNotOptimize(ids.data());
    }
  }
  report(state, side);
  rtcReleaseScene(rtc);
  rtcReleaseDevice(device);
}

void run_pass(benchmark::State& state, const g2p::RenderOptions& options) {
  const Scene& s = scene();
  std::unique_ptr<g2p::Renderer> renderer = std::move(*g2p::renderer_registry().create("embree"));
  if (g2p::Status st = renderer->set_model(s.model); !st.ok()) state.SkipWithError(st.message().c_str());
  g2p::View view;  // reused across views, as the bare loop reuses its buffer
  for (auto _ : state) {
    for (const g2p::Camera& cam : s.cameras) {
      g2p::Status st = renderer->render_into(cam, options, view);
      benchmark::DoNotOptimize(st);
    }
  }
  report(state);
}

void BM_FaceIdPass(benchmark::State& state) {
  g2p::RenderOptions o;
  o.shade = o.material_buffers = o.geometry_buffers = false;
  run_pass(state, o);
}

void BM_FullPass(benchmark::State& state) { run_pass(state, g2p::RenderOptions{}); }

// What the render stage does: every view into a View of its own (fresh
// memory), all buffers; the scene is built once outside the timing.
void BM_RenderViews(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  std::unique_ptr<g2p::Renderer> renderer = std::move(*g2p::renderer_registry().create("embree"));
  if (g2p::Status st = renderer->set_model(scene().model); !st.ok()) state.SkipWithError(st.message().c_str());
  for (auto _ : state) {
    std::vector<g2p::View> views(cameras(side).size());
    for (std::size_t i = 0; i < views.size(); ++i) {
      g2p::Status st = renderer->render_into(cameras(side)[i], g2p::RenderOptions{}, views[i]);
      benchmark::DoNotOptimize(st);
    }
    benchmark::DoNotOptimize(views.data());
  }
  report(state, side);
}

void BM_SceneBuild(benchmark::State& state) {
  std::unique_ptr<g2p::Renderer> renderer = std::move(*g2p::renderer_registry().create("embree"));
  for (auto _ : state) benchmark::DoNotOptimize(renderer->set_model(scene().model));
  state.counters["triangles"] = static_cast<double>(scene().model.mesh.num_faces());
}

BENCHMARK(BM_BareEmbreeLoop)->Arg(512)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FaceIdPass)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FullPass)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderViews)->Arg(512)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SceneBuild)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
