// The CGAL completers of the optional GPL component g2p::cgal: `alpha-wrap`
// and `fill` on closed and open patches, their settings, their registration,
// and complete()'s fallback for the parts `fill` cannot close.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "complete/complete_fixtures.h"
#include "g2p/complete.h"
#include "g2p/complete_cgal.h"
#include "support/gltf_builder.h"

namespace g2p {
namespace {

// The backend's own behaviour: no part kept as given, no volume check (both
// are complete()'s, tested in closed_parts_test.cpp).
const CompletionOptions kBackendOnly = [] {
  CompletionOptions o;
  o.keep_closed_parts = false;
  o.volume_tolerance = 0.0;
  return o;
}();

constexpr int kWood = static_cast<int>(PaperClass::kWood);
constexpr int kMetal = static_cast<int>(PaperClass::kMetal);

// An open tube along z (no caps): radius r, length h, `n` sides.
Mesh open_tube(double r, double h, int n) {
  Mesh tube;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < n; ++i)
      tube.positions.emplace_back(r * std::cos(2 * M_PI * i / n), r * std::sin(2 * M_PI * i / n), h * ring);
  for (int i = 0; i < n; ++i) {
    tube.triangles.emplace_back(i, (i + 1) % n, n + (i + 1) % n);
    tube.triangles.emplace_back(i, n + (i + 1) % n, n + i);
  }
  return tube;
}

// `mesh` without the triangles listed in `drop`.
Mesh without_faces(const Mesh& mesh, std::initializer_list<int> drop) {
  Mesh out = mesh;
  out.triangles.clear();
  for (int f = 0; f < mesh.num_faces(); ++f)
    if (std::find(drop.begin(), drop.end(), f) == drop.end())
      out.triangles.push_back(mesh.triangles[static_cast<std::size_t>(f)]);
  return out;
}

std::unique_ptr<Completer> completer(const std::string& name, const BackendSettings& settings = {}) {
  EXPECT_TRUE(register_cgal_completers().ok());
  Result<std::unique_ptr<Completer>> c = make_completer(name, settings);
  EXPECT_TRUE(c.ok()) << c.status().to_string();
  return c.ok() ? std::move(*c) : nullptr;
}

// Runs `c` on `mesh` as one part; returns that part (and the seconds taken).
CompletedPart run_single(const Completer& c, const Mesh& mesh, double* seconds = nullptr) {
  const std::vector<Part> parts = test::single_part(mesh, kWood);
  const auto start = std::chrono::steady_clock::now();
  Result<Completion> r = complete({&mesh, &parts, nullptr}, c, nullptr, kBackendOnly);
  if (seconds != nullptr) *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  if (!r.ok() || r->parts.size() != 1) return {};
  return std::move(r->parts[0]);
}

std::string notes_of(const CompletedPart& p) {
  std::string all;
  for (const std::string& n : p.notes) all += n + "\n";
  return all;
}

void expect_watertight(const CompletedPart& p) {
  EXPECT_TRUE(p.checks.closed);
  EXPECT_TRUE(p.checks.manifold);
  EXPECT_TRUE(p.checks.outward);
  EXPECT_TRUE(p.checks.self_intersections_checked);
  EXPECT_TRUE(p.checks.self_intersection_free) << p.checks.num_self_intersections << " self-intersections";
  EXPECT_EQ(p.checks.num_components, 1);
  EXPECT_TRUE(p.checks.watertight());
  EXPECT_GT(p.checks.volume_m3, 0.0);
}

TEST(CgalCompleters, AlphaWrapKeepsAClosedBox) {
  const Mesh box = test::box_mesh({0, 0, 0}, {0.3f, 0.2f, 0.1f});
  auto c = completer("alpha-wrap");
  ASSERT_NE(c, nullptr);
  double seconds = 0;
  const CompletedPart p = run_single(*c, box, &seconds);
  expect_watertight(p);
  EXPECT_TRUE(p.ok) << notes_of(p);
  EXPECT_EQ(p.backend, "alpha-wrap");
  const double ratio = p.checks.volume_m3 / 0.006;
  std::printf("alpha-wrap box: volume ratio %.4f, %d triangles, %.2f s\n", ratio, p.mesh.num_faces(), seconds);
  EXPECT_NEAR(ratio, 1.0, 0.02) << notes_of(p);
  EXPECT_LT(p.checks.relative_distance, 0.01);
  EXPECT_NE(notes_of(p).find("alpha"), std::string::npos);
  EXPECT_EQ(notes_of(p).find("open"), std::string::npos) << notes_of(p);
}

TEST(CgalCompleters, AlphaWrapKeepsASphere) {
  const Mesh sphere = test::sphere_mesh(0.1, 24);
  const double volume = test::signed_volume(sphere.positions, sphere.triangles);
  auto c = completer("alpha-wrap");
  ASSERT_NE(c, nullptr);
  double seconds = 0;
  const CompletedPart p = run_single(*c, sphere, &seconds);
  expect_watertight(p);
  EXPECT_TRUE(p.ok) << notes_of(p);
  const double ratio = p.checks.volume_m3 / volume;
  std::printf("alpha-wrap sphere: volume ratio %.4f, %d triangles, %.2f s\n", ratio, p.mesh.num_faces(), seconds);
  EXPECT_NEAR(ratio, 1.0, 0.02) << notes_of(p);
}

TEST(CgalCompleters, AlphaWrapClosesAnOpenTube) {
  const Mesh tube = open_tube(0.05, 0.2, 16);
  auto c = completer("alpha-wrap");
  ASSERT_NE(c, nullptr);
  double seconds = 0;
  const CompletedPart p = run_single(*c, tube, &seconds);
  std::printf("alpha-wrap open tube: volume %.3g m^3, %d triangles, %.2f s\n", p.checks.volume_m3, p.mesh.num_faces(),
              seconds);
  expect_watertight(p);
  // alpha is far below the mouth's width: a thin shell, not a solid; the
  // notes say so and the part is not ok, so complete() falls back.
  EXPECT_FALSE(p.ok) << notes_of(p);
  EXPECT_NE(notes_of(p).find("2 hole(s)"), std::string::npos) << notes_of(p);
  EXPECT_NE(notes_of(p).find("thin shell"), std::string::npos) << notes_of(p);
  // With an alpha wider than the tube's mouth the wrap closes over the ends.
  auto wide = completer("alpha-wrap", {{"relative_alpha", "0.6"}, {"relative_offset", "0.002"}});
  ASSERT_NE(wide, nullptr);
  const CompletedPart q = run_single(*wide, tube);
  expect_watertight(q);
  EXPECT_TRUE(q.ok) << notes_of(q);
  EXPECT_EQ(notes_of(q).find("thin shell"), std::string::npos) << notes_of(q);
  const double cylinder = M_PI * 0.05 * 0.05 * 0.2;
  std::printf("alpha-wrap open tube, wide alpha: volume ratio %.4f to the capped tube\n",
              q.checks.volume_m3 / cylinder);
  EXPECT_GT(q.checks.volume_m3, 0.8 * cylinder);
}

TEST(CgalCompleters, AlphaWrapsEveryPart) {
  Mesh mesh = test::box_mesh({0, 0, 0}, {0.3f, 0.2f, 0.1f});
  Mesh ball = test::sphere_mesh(0.05, 12);
  for (auto& q : ball.positions) q += Eigen::Vector3f(1.0f, 0, 0);
  const int first_ball = test::append_mesh(mesh, ball);
  std::vector<Part> parts(2);
  parts[0].label = kWood;
  parts[1].label = kMetal;
  for (int f = 0; f < mesh.num_faces(); ++f) parts[f < first_ball ? 0 : 1].faces.push_back(f);
  auto c = completer("alpha-wrap");
  ASSERT_NE(c, nullptr);
  Result<Completion> r = complete({&mesh, &parts, nullptr}, *c, nullptr, kBackendOnly);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r->parts.size(), 2u);
  EXPECT_EQ(r->parts[1].label, kMetal);
  for (const CompletedPart& p : r->parts) {
    expect_watertight(p);
    EXPECT_TRUE(p.ok);
  }
  // Each part is wrapped on its own: the ball's wrap stays near the ball.
  EXPECT_GT(bounds(r->parts[1].mesh).min().x(), 0.9);
  EXPECT_NEAR(r->parts_volume_m3, r->parts[0].checks.volume_m3 + r->parts[1].checks.volume_m3, 1e-12);
}

TEST(CgalCompleters, FillClosesABoxWithAMissingEnd) {
  // A long box without its x = max end (faces 10 and 11): the hole is small next to the part.
  const Mesh box = test::box_mesh({0, 0, 0}, {0.6f, 0.1f, 0.1f});
  const Mesh open = without_faces(box, {10, 11});
  auto c = completer("fill");
  ASSERT_NE(c, nullptr);
  double seconds = 0;
  const CompletedPart p = run_single(*c, open, &seconds);
  expect_watertight(p);
  EXPECT_TRUE(p.ok) << notes_of(p);
  EXPECT_EQ(p.backend, "fill");
  const double ratio = p.checks.volume_m3 / 0.006;
  std::printf("fill box end: volume ratio %.4f, %d triangles, %.3f s\n", ratio, p.mesh.num_faces(), seconds);
  EXPECT_NEAR(ratio, 1.0, 0.02) << notes_of(p);
  EXPECT_NE(notes_of(p).find("filled 1 hole"), std::string::npos) << notes_of(p);
}

TEST(CgalCompleters, FillFairsAHoleInACurvedPatch) {
  // A sphere without its north cap (the first 2n triangles, around the pole):
  // the refined, faired fill follows the sphere.
  const int n = 24;
  const Mesh sphere = test::sphere_mesh(0.1, n);
  Mesh open = sphere;
  open.triangles.erase(open.triangles.begin(), open.triangles.begin() + 2 * n);
  auto c = completer("fill");
  ASSERT_NE(c, nullptr);
  double seconds = 0;
  const CompletedPart p = run_single(*c, open, &seconds);
  expect_watertight(p);
  EXPECT_TRUE(p.ok) << notes_of(p);
  const double ratio = p.checks.volume_m3 / test::signed_volume(sphere.positions, sphere.triangles);
  std::printf("fill sphere cap: volume ratio %.5f, %d triangles (sphere %d), %.3f s\n", ratio, p.mesh.num_faces(),
              sphere.num_faces(), seconds);
  EXPECT_NEAR(ratio, 1.0, 0.005) << notes_of(p);
}

TEST(CgalCompleters, FillClosesABoxWithoutItsTopWhenAllowed) {
  // The top (faces 2 and 3) of a flat box spans most of the part's diagonal:
  // too wide by default, filled flat when max_relative_hole allows it.
  const Mesh box = test::box_mesh({0, 0, 0}, {0.3f, 0.2f, 0.1f});
  const Mesh open = without_faces(box, {2, 3});
  auto strict = completer("fill");
  ASSERT_NE(strict, nullptr);
  const CompletedPart refused = run_single(*strict, open);
  EXPECT_FALSE(refused.ok);
  EXPECT_NE(notes_of(refused).find("max_relative_hole"), std::string::npos) << notes_of(refused);
  auto lenient = completer("fill", {{"max_relative_hole", "1"}});
  ASSERT_NE(lenient, nullptr);
  const CompletedPart p = run_single(*lenient, open);
  expect_watertight(p);
  EXPECT_TRUE(p.ok) << notes_of(p);
  const double ratio = p.checks.volume_m3 / 0.006;
  std::printf("fill box top (max_relative_hole 1): volume ratio %.4f, %d triangles\n", ratio, p.mesh.num_faces());
  EXPECT_NEAR(ratio, 1.0, 0.02) << notes_of(p);
}

TEST(CgalCompleters, FillKeepsAClosedPatch) {
  const Mesh box = test::box_mesh({0, 0, 0}, {0.3f, 0.2f, 0.1f});
  auto c = completer("fill");
  ASSERT_NE(c, nullptr);
  const CompletedPart p = run_single(*c, box);
  expect_watertight(p);
  EXPECT_TRUE(p.ok);
  EXPECT_EQ(p.mesh.num_faces(), 12);
  EXPECT_NEAR(p.checks.volume_m3, 0.006, 1e-7);
  EXPECT_NE(notes_of(p).find("already closed"), std::string::npos);
}

TEST(CgalCompleters, FillMakesInwardPatchesOutward) {
  Mesh box = test::box_mesh({0, 0, 0}, {0.6f, 0.1f, 0.1f});
  for (auto& t : box.triangles) std::swap(t[1], t[2]);
  auto c = completer("fill");
  ASSERT_NE(c, nullptr);
  const CompletedPart p = run_single(*c, without_faces(box, {10, 11}));
  expect_watertight(p);
  EXPECT_TRUE(p.ok) << notes_of(p);
  EXPECT_NEAR(p.checks.volume_m3, 0.006, 1e-7);
}

TEST(CgalCompleters, FillFallsBackOnAHugeHole) {
  const Mesh tube = open_tube(0.05, 0.2, 16);
  const std::vector<Part> parts = test::single_part(tube, kWood);
  auto fill = completer("fill");
  ASSERT_NE(fill, nullptr);
  Result<Completion> alone = complete({&tube, &parts, nullptr}, *fill, nullptr, kBackendOnly);
  ASSERT_TRUE(alone.ok()) << alone.status().to_string();
  ASSERT_EQ(alone->parts.size(), 1u);
  EXPECT_FALSE(alone->parts[0].ok);
  EXPECT_NE(notes_of(alone->parts[0]).find("max_relative_hole"), std::string::npos) << notes_of(alone->parts[0]);

  Result<std::unique_ptr<Completer>> partition = make_completer("partition", {{"resolution", "64"}});
  ASSERT_TRUE(partition.ok()) << partition.status().to_string();
  Result<Completion> r = complete({&tube, &parts, nullptr}, *fill, partition->get(), kBackendOnly);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r->parts.size(), 1u);
  const CompletedPart& p = r->parts[0];
  EXPECT_TRUE(p.ok) << notes_of(p);
  EXPECT_EQ(p.backend, "partition");
  EXPECT_NE(notes_of(p).find("max_relative_hole"), std::string::npos) << notes_of(p);
  EXPECT_NE(notes_of(p).find("fell back to 'partition'"), std::string::npos) << notes_of(p);
}

TEST(CgalCompleters, FillFailsGracefullyOnNonManifoldPatches) {
  // A box with a fin: a third triangle on one of its edges (a non-manifold edge).
  Mesh finned = test::box_mesh({0, 0, 0}, {0.6f, 0.1f, 0.1f});
  finned.positions.emplace_back(0.3f, -0.2f, -0.2f);
  finned.triangles.emplace_back(0, 1, finned.num_vertices() - 1);
  // A patch of only degenerate triangles.
  Mesh degenerate;
  degenerate.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  degenerate.triangles = {{0, 1, 2}, {0, 0, 1}};
  auto c = completer("fill");
  ASSERT_NE(c, nullptr);
  for (const Mesh* m : {&finned, &degenerate}) {
    const CompletedPart p = run_single(*c, *m);
    EXPECT_FALSE(p.ok);
    EXPECT_FALSE(p.notes.empty());
    std::printf("fill on a bad patch: %s", notes_of(p).c_str());
  }
  // Holes allowed anywhere: a lone triangle and the degenerate patch still fail cleanly.
  Mesh triangle;
  triangle.positions = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}};
  triangle.triangles = {{0, 1, 2}};
  auto lenient = completer("fill", {{"max_relative_hole", "10"}});
  ASSERT_NE(lenient, nullptr);
  for (const Mesh* m : {&triangle, &degenerate}) {
    const CompletedPart p = run_single(*lenient, *m);
    EXPECT_FALSE(p.ok);
    EXPECT_FALSE(p.notes.empty());
  }
  // alpha-wrap has nothing to wrap in a patch of degenerate triangles.
  auto wrap = completer("alpha-wrap");
  ASSERT_NE(wrap, nullptr);
  const CompletedPart w = run_single(*wrap, degenerate);
  EXPECT_FALSE(w.ok);
  EXPECT_FALSE(w.notes.empty());
  std::printf("alpha-wrap on a degenerate patch: %s", notes_of(w).c_str());
  // An empty part is a note too, for both backends.
  const Mesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  std::vector<Part> empty(1);
  for (const char* name : {"fill", "alpha-wrap"}) {
    auto b = completer(name);
    ASSERT_NE(b, nullptr);
    Result<Completion> r = complete({&box, &empty, nullptr}, *b, nullptr, kBackendOnly);
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r->parts.size(), 1u);
    EXPECT_FALSE(r->parts[0].ok);
    EXPECT_FALSE(r->parts[0].notes.empty());
  }
}

TEST(CgalCompleters, RejectsBadSettings) {
  ASSERT_TRUE(register_cgal_completers().ok());
  const struct {
    std::string backend, key, value;
  } bad[] = {
      {"alpha-wrap", "relative_alpha", "0"},
      {"alpha-wrap", "relative_alpha", "-1"},
      {"alpha-wrap", "relative_offset", "abc"},
      {"alpha-wrap", "relative_offset", "0.1x"},
      {"alpha-wrap", "max_relative_distance", "nan"},
      {"alpha-wrap", "alpha", "0.1"},
      {"fill", "max_relative_hole", "0"},
      {"fill", "fairing_continuity", "3"},
      {"fill", "max_relative_distance", ""},
      {"fill", "resolution", "64"},
  };
  for (const auto& b : bad) {
    SCOPED_TRACE(b.backend + " " + b.key + "=" + b.value);
    Result<std::unique_ptr<Completer>> c = make_completer(b.backend, {{b.key, b.value}});
    ASSERT_FALSE(c.ok());
    EXPECT_EQ(c.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(c.status().message().find(b.key), std::string::npos) << c.status().message();
  }
  EXPECT_TRUE(make_completer("alpha-wrap", {{"relative_alpha", "0.02"}, {"relative_offset", "0.0005"}}).ok());
  EXPECT_TRUE(make_completer("fill", {{"max_relative_hole", "0.5"}, {"fairing_continuity", "0"}}).ok());
}

TEST(CgalCompleters, RegistrationIsIdempotent) {
  EXPECT_TRUE(register_cgal_completers().ok());
  EXPECT_TRUE(register_cgal_completers().ok());
  const std::vector<std::string> names = completer_registry().names();
  EXPECT_EQ(std::count(names.begin(), names.end(), "alpha-wrap"), 1);
  EXPECT_EQ(std::count(names.begin(), names.end(), "fill"), 1);
  EXPECT_TRUE(completer_registry().contains("partition"));
  EXPECT_TRUE(make_completer("alpha-wrap").ok());
  EXPECT_TRUE(make_completer("fill").ok());
  EXPECT_NE(make_alpha_wrap_completer(), nullptr);
  EXPECT_NE(make_fill_completer(), nullptr);
}

}  // namespace
}  // namespace g2p
