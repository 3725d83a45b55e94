// Parts that are already solids are kept as given, and every completed part
// is held to the volume the input's faces enclose (#50).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "complete/complete_fixtures.h"
#include "g2p/complete.h"
#include "support/gltf_builder.h"

namespace g2p {
namespace {

// Every triangle with its own three vertices, as a flat-shaded glTF stores a
// box: nothing is shared until welding.
Mesh split_vertices(const Mesh& m) {
  Mesh out;
  for (const auto& t : m.triangles) {
    const int base = out.num_vertices();
    for (int k = 0; k < 3; ++k) out.positions.push_back(m.positions[static_cast<std::size_t>(t[k])]);
    out.triangles.emplace_back(base, base + 1, base + 2);
  }
  return out;
}

Mesh turned_inside_out(Mesh m) {
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

Mesh cylinder_mesh(float radius, float length, int segments) {
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::cylinder_geometry(radius, 0.0f, length, segments, p, t);
  return test::mesh_from_geometry(p, t);
}

// The volume of a closed mesh by the divergence theorem, in double.
double exact_volume(const Mesh& m) {
  double six_v = 0.0;
  for (const auto& t : m.triangles)
    six_v += m.positions[static_cast<std::size_t>(t[0])].cast<double>().dot(
        m.positions[static_cast<std::size_t>(t[1])].cast<double>().cross(
            m.positions[static_cast<std::size_t>(t[2])].cast<double>()));
  return six_v / 6.0;
}

// A 600 x 300 x 2 mm board (z from 0 to 2 mm) given as its two large faces
// only: open along its edges.
Mesh edgeless_board() {
  const Mesh board = test::box_mesh({0, 0, 0}, {0.6f, 0.3f, 0.002f});
  Mesh faces;
  faces.positions = board.positions;
  for (const auto& t : board.triangles) {
    const float z0 = board.positions[static_cast<std::size_t>(t[0])].z();
    if (z0 == board.positions[static_cast<std::size_t>(t[1])].z() &&
        z0 == board.positions[static_cast<std::size_t>(t[2])].z())
      faces.triangles.push_back(t);
  }
  return faces;
}

// The two faces of the edge-less board as two parts, bottom (0) and top (1).
std::vector<Part> board_faces_as_parts(const Mesh& faces) {
  std::vector<Part> parts(2);
  for (int f = 0; f < faces.num_faces(); ++f) {
    const bool top =
        faces.positions[static_cast<std::size_t>(faces.triangles[static_cast<std::size_t>(f)][0])].z() > 0.001f;
    parts[top ? 1 : 0].label = 1;
    parts[top ? 1 : 0].faces.push_back(f);
  }
  return parts;
}

Result<Completion> complete_with_partition(const Mesh& mesh, const std::vector<Part>& parts,
                                           const CompletionOptions& options = {},
                                           const BackendSettings& settings = {}) {
  Result<std::unique_ptr<Completer>> partition = make_completer("partition", settings);
  if (!partition.ok()) return partition.status();
  return complete(CompletionInput{&mesh, &parts, nullptr, nullptr, 0.0, {}}, **partition, nullptr, options);
}

struct ClosedCase {
  const char* name;
  Mesh mesh;
};

TEST(ClosedParts, BoxesPlatesAndRodsKeepTheirExactVolume) {
  // The inputs: boards 1 to 20 mm thick, a 1 mm plate, an 8 mm rod,
  // each with its vertices split per triangle.
  const std::vector<ClosedCase> cases = {
      {"board 600 x 300 x 2 mm", test::box_mesh({0, 0, 0}, {0.6f, 0.3f, 0.002f})},
      {"plate 200 x 200 x 1 mm", test::box_mesh({0, 0, 0}, {0.2f, 0.2f, 0.001f})},
      {"board 600 x 300 x 5 mm", test::box_mesh({0, 0, 0}, {0.6f, 0.3f, 0.005f})},
      {"board 800 x 500 x 20 mm", test::box_mesh({0, 0, 0}, {0.8f, 0.5f, 0.02f})},
      {"block 50 mm", test::box_mesh({0, 0, 0}, {0.05f, 0.05f, 0.05f})},
      {"rod 8 mm x 1 m", cylinder_mesh(0.004f, 1.0f, 24)},
  };
  for (const ClosedCase& c : cases) {
    SCOPED_TRACE(c.name);
    const Mesh mesh = split_vertices(c.mesh);
    const double truth = exact_volume(c.mesh);
    Result<Completion> done = complete_with_partition(mesh, test::single_part(mesh, 1));
    ASSERT_TRUE(done.ok()) << done.status().message();
    ASSERT_EQ(done->parts.size(), 1u);
    const CompletedPart& p = done->parts[0];
    EXPECT_EQ(p.backend, "input");
    EXPECT_TRUE(p.ok);
    EXPECT_EQ(done->kept_parts, 1);
    EXPECT_NEAR(p.checks.volume_m3, truth, 1e-9 * truth + 1e-15);
    EXPECT_EQ(p.mesh.num_faces(), c.mesh.num_faces());  // no larger than the input's part
    EXPECT_EQ(p.mesh.num_vertices(), c.mesh.num_vertices());
    // The independent estimate agrees with the exact volume.
    ASSERT_GT(p.input_volume_m3, 0.0);
    EXPECT_NEAR(p.input_volume_m3 / truth, 1.0, 0.01);
    ASSERT_TRUE(std::isfinite(p.volume_difference));
    EXPECT_LT(std::abs(p.volume_difference), 0.01);
  }
}

TEST(ClosedParts, AnInsideOutSolidIsTurnedAndACavityStays) {
  const Mesh box = test::box_mesh({0, 0, 0}, {0.2f, 0.1f, 0.1f});
  const Mesh inverted = turned_inside_out(box);
  const Mesh kept = closed_part_surface(inverted, test::single_part(inverted, 1)[0]);
  ASSERT_GT(kept.num_faces(), 0);
  EXPECT_NEAR(exact_volume(kept), exact_volume(box), 1e-12);

  // A hollow box: the outer surface outward, the inner one inward (a cavity).
  Mesh hollow = test::box_mesh({0, 0, 0}, {0.2f, 0.2f, 0.2f});
  test::append_mesh(hollow, turned_inside_out(test::box_mesh({0.05f, 0.05f, 0.05f}, {0.15f, 0.15f, 0.15f})));
  const double truth = 0.2 * 0.2 * 0.2 - 0.1 * 0.1 * 0.1;
  Mesh shell = closed_part_surface(hollow, test::single_part(hollow, 1)[0]);
  ASSERT_GT(shell.num_faces(), 0);
  EXPECT_NEAR(exact_volume(shell), truth, 1e-9);
  // Both surfaces wound outward, as some exporters write them: a cavity or a
  // second solid inside the first? Not clearly a solid; left to the completer.
  Mesh both_out = test::box_mesh({0, 0, 0}, {0.2f, 0.2f, 0.2f});
  test::append_mesh(both_out, test::box_mesh({0.05f, 0.05f, 0.05f}, {0.15f, 0.15f, 0.15f}));
  EXPECT_EQ(closed_part_surface(both_out, test::single_part(both_out, 1)[0]).num_faces(), 0);
  // Two separate solids, one of them inside out: that one is turned.
  Mesh pair = test::box_mesh({0, 0, 0}, {0.1f, 0.1f, 0.1f});
  test::append_mesh(pair, turned_inside_out(test::box_mesh({0.3f, 0, 0}, {0.4f, 0.1f, 0.1f})));
  const Mesh two = closed_part_surface(pair, test::single_part(pair, 1)[0]);
  ASSERT_GT(two.num_faces(), 0);
  EXPECT_NEAR(exact_volume(two), 2e-3, 1e-9);
}

TEST(ClosedParts, OpenOverlappingOrSelfIntersectingFacesAreNotKept) {
  // One face missing: open.
  Mesh open = test::box_mesh({0, 0, 0}, {0.2f, 0.1f, 0.1f});
  open.triangles.pop_back();
  EXPECT_EQ(closed_part_surface(open, test::single_part(open, 1)[0]).num_faces(), 0);
  // Two solids overlapping: each closed, together not the boundary of a solid.
  Mesh overlapping = test::box_mesh({0, 0, 0}, {0.2f, 0.2f, 0.2f});
  test::append_mesh(overlapping, test::box_mesh({0.1f, 0.1f, 0.1f}, {0.3f, 0.3f, 0.3f}));
  EXPECT_EQ(closed_part_surface(overlapping, test::single_part(overlapping, 1)[0]).num_faces(), 0);
  // The same box twice (a doubled shell): welded, every edge has four faces.
  Mesh doubled = test::box_mesh({0, 0, 0}, {0.2f, 0.2f, 0.2f});
  test::append_mesh(doubled, test::box_mesh({0, 0, 0}, {0.2f, 0.2f, 0.2f}));
  EXPECT_EQ(closed_part_surface(doubled, test::single_part(doubled, 1)[0]).num_faces(), 0);

  // The completer closes what is not kept; a part without faces of its own
  // closed is not marked as kept.
  Result<Completion> done = complete_with_partition(open, test::single_part(open, 1));
  ASSERT_TRUE(done.ok()) << done.status().message();
  EXPECT_EQ(done->parts[0].backend, "partition");
  EXPECT_EQ(done->kept_parts, 0);
}

TEST(ClosedParts, CopiesWithinTheWeldToleranceJoinAndNoOthers) {
  // A cylinder with every triangle's own vertices, each copy moved by up to
  // 0.45 of the weld distance in a random direction: any two copies of a
  // corner lie within it, wherever they fall on the weld's grid.
  const Mesh solid = cylinder_mesh(0.1f, 0.3f, 48);
  const double tolerance = 1e-3;
  const double eps = tolerance * bounds(solid).diagonal().norm();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto moved = [&](double distance) {
    Mesh m = split_vertices(solid);
    for (auto& p : m.positions) {
      Eigen::Vector3d d(unit(random), unit(random), unit(random));
      p += (distance * d.normalized()).cast<float>();
    }
    return m;
  };
  const Mesh jittered = moved(0.45 * eps);
  const Mesh kept = closed_part_surface(jittered, test::single_part(jittered, 1)[0], tolerance);
  EXPECT_EQ(kept.num_faces(), solid.num_faces());
  EXPECT_EQ(kept.num_vertices(), solid.num_vertices());
  EXPECT_NEAR(exact_volume(kept) / exact_volume(solid), 1.0, 1e-3);

  // Copies 1.1 weld distances apart along x do not join: the faces stay open.
  Mesh apart = split_vertices(solid);
  std::vector<int> copies(static_cast<std::size_t>(solid.num_vertices()), 0);
  for (std::size_t f = 0; f < solid.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int n = copies[static_cast<std::size_t>(solid.triangles[f][k])]++;
      apart.positions[3 * f + static_cast<std::size_t>(k)].x() += static_cast<float>(1.1 * eps * n);
    }
  EXPECT_EQ(closed_part_surface(apart, test::single_part(apart, 1)[0], tolerance).num_faces(), 0);
}

TEST(ClosedParts, OnlyTheOpenPartsAreCompleted) {
  // A closed steel block on an open wooden tray (a box without its top).
  Mesh mesh = test::box_mesh({0.05f, 0.05f, 0.01f}, {0.1f, 0.1f, 0.06f});
  const int tray_first = test::append_mesh(mesh, test::box_mesh({0, 0, 0}, {0.3f, 0.3f, 0.01f}));
  mesh.triangles.erase(mesh.triangles.begin() + tray_first + 2, mesh.triangles.begin() + tray_first + 4);
  std::vector<Part> parts(2);
  parts[0].label = 1;
  parts[1].label = 2;
  for (int f = 0; f < mesh.num_faces(); ++f) (f < tray_first ? parts[0] : parts[1]).faces.push_back(f);
  Result<Completion> done = complete_with_partition(mesh, parts);
  ASSERT_TRUE(done.ok()) << done.status().message();
  EXPECT_EQ(done->parts[0].backend, "input");
  EXPECT_NEAR(done->parts[0].checks.volume_m3, 0.05 * 0.05 * 0.05, 1e-12);
  EXPECT_EQ(done->parts[1].backend, "partition");
  EXPECT_EQ(done->kept_parts, 1);
  // Without keeping, the completer closes both (the ablation).
  CompletionOptions closing_all;
  closing_all.keep_closed_parts = false;
  done = complete_with_partition(mesh, parts, closing_all);
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->parts[0].backend, "partition");
  EXPECT_EQ(done->kept_parts, 0);
}

TEST(VolumeEstimate, MeasuresClosedSurfacesAndSplitsBetweenParts) {
  // Two boxes side by side, sharing the plane x = 0.1: each part's estimate
  // is its own box, whichever way the rays cross.
  Mesh mesh = test::box_mesh({0, 0, 0}, {0.1f, 0.1f, 0.1f});
  const int second = test::append_mesh(mesh, test::box_mesh({0.1f, 0, 0}, {0.3f, 0.1f, 0.1f}));
  std::vector<Part> parts(2);
  for (int f = 0; f < mesh.num_faces(); ++f) parts[f < second ? 0 : 1].faces.push_back(f);
  const VolumeEstimate e = estimate_volumes(mesh, parts);
  ASSERT_TRUE(e.usable());
  EXPECT_EQ(e.rays_paired, e.rays_hit);
  EXPECT_NEAR(e.object_m3, 3e-3, 3e-3 * 0.005);
  EXPECT_NEAR(e.part_m3[0], 1e-3, 1e-3 * 0.01);
  EXPECT_NEAR(e.part_m3[1], 2e-3, 2e-3 * 0.01);
  EXPECT_GT(e.part_own_fraction[0], 0.99);
  // A sphere: sampled, within a percent.
  const Mesh sphere = test::sphere_mesh(0.05, 48);
  const VolumeEstimate s = estimate_volumes(sphere, test::single_part(sphere, 1));
  EXPECT_NEAR(s.object_m3 / exact_volume(sphere), 1.0, 0.01);
  // Inside out, the same volume.
  const Mesh inverted = turned_inside_out(sphere);
  EXPECT_NEAR(estimate_volumes(inverted, test::single_part(inverted, 1)).object_m3 / exact_volume(sphere), 1.0, 0.01);
  // A single sheet encloses nothing: every ray crosses it once.
  Mesh sheet = test::box_mesh({0, 0, 0}, {0.3f, 0.3f, 0.01f});
  sheet.triangles.resize(2);  // one face of the box
  const VolumeEstimate open = estimate_volumes(sheet, test::single_part(sheet, 1));
  EXPECT_FALSE(open.usable());
  EXPECT_GT(open.rays_hit, 0);
  EXPECT_EQ(open.rays_paired, 0);
}

TEST(VolumeEstimate, AThinPartTheCompleterCannotResolveIsFlagged) {
  // A 600 x 300 x 2 mm board given as its two faces only (no edges): open,
  // so the completer must close it, but the rays through both faces measure
  // its volume. Whatever the completer makes of it, a volume off by more
  // than the tolerance fails the part with a note saying by how much.
  const Mesh faces = edgeless_board();
  ASSERT_EQ(faces.num_faces(), 4);
  CompletionOptions first_pass_only;  // the grid's result as it is (ThinParts below resolves it)
  first_pass_only.resolve_thin_parts = false;
  Result<Completion> done = complete_with_partition(faces, test::single_part(faces, 1), first_pass_only);
  ASSERT_TRUE(done.ok()) << done.status().message();
  const CompletedPart& p = done->parts[0];
  EXPECT_EQ(p.backend, "partition");
  EXPECT_NEAR(p.input_volume_m3, 0.6 * 0.3 * 0.002, 0.6 * 0.3 * 0.002 * 0.01);
  EXPECT_NEAR(done->input_volume_m3, 0.6 * 0.3 * 0.002, 0.6 * 0.3 * 0.002 * 0.01);
  ASSERT_TRUE(std::isfinite(p.volume_difference));
  EXPECT_NEAR(p.volume_difference, p.checks.volume_m3 / p.input_volume_m3 - 1.0, 1e-9);
  bool noted = false;
  for (const std::string& n : p.notes) noted |= n.rfind("volume check: ", 0) == 0;
  if (std::abs(p.volume_difference) > CompletionOptions().volume_tolerance) {
    EXPECT_FALSE(p.ok);
    EXPECT_TRUE(noted);
  } else {
    EXPECT_FALSE(noted);
  }
  // A tolerance below the difference always fails it.
  CompletionOptions strict = first_pass_only;
  strict.volume_tolerance = 0.5 * std::abs(p.volume_difference);
  done = complete_with_partition(faces, test::single_part(faces, 1), strict);
  ASSERT_TRUE(done.ok());
  EXPECT_FALSE(done->parts[0].ok);
}

TEST(VolumeEstimate, TheObjectIsJudgedWhereNoPartCanBeAlone) {
  // The edge-less 2 mm board again, its two faces two parts (as the project
  // stage makes them: they share no edge). Every interval runs from one part
  // to the other, so neither is judged alone; the object is.
  const Mesh faces = edgeless_board();
  const std::vector<Part> parts = board_faces_as_parts(faces);
  CompletionOptions strict;  // below any difference a grid can leave on a board this thin
  strict.volume_tolerance = 0.001;
  strict.resolve_thin_parts = false;
  Result<Completion> done = complete_with_partition(faces, parts, strict);
  ASSERT_TRUE(done.ok()) << done.status().message();
  EXPECT_NEAR(done->input_volume_m3, 0.6 * 0.3 * 0.002, 0.6 * 0.3 * 0.002 * 0.01);
  bool object_noted = false;
  for (const std::string& n : done->notes) object_noted |= n.rfind("volume check: the parts together hold", 0) == 0;
  EXPECT_TRUE(object_noted);
  for (const CompletedPart& p : done->parts) {
    SCOPED_TRACE("part " + std::to_string(p.part));
    EXPECT_FALSE(std::isfinite(p.volume_difference));  // not judged alone
    EXPECT_FALSE(p.ok);
  }
  // At the default tolerance the verdict follows the measured difference.
  done = complete_with_partition(faces, parts);
  ASSERT_TRUE(done.ok());
  const double off = (done->parts_volume_m3 - done->input_volume_m3) / done->input_volume_m3;
  bool noted = false;
  for (const std::string& n : done->notes) noted |= n.rfind("volume check: the parts together hold", 0) == 0;
  EXPECT_EQ(noted, std::abs(off) > CompletionOptions().volume_tolerance) << off;
}

TEST(ThinParts, ABoardGivenAsItsFacesIsClosedAsAShellOfItsThickness) {
  const double board = 0.6 * 0.3 * 0.002;
  const Mesh faces = edgeless_board();
  // One part: its two faces are two pieces, each takes half the thickness.
  Result<Completion> done = complete_with_partition(faces, test::single_part(faces, 1));
  ASSERT_TRUE(done.ok()) << done.status().message();
  const CompletedPart& one = done->parts[0];
  EXPECT_EQ(one.backend, "shell");
  EXPECT_TRUE(one.ok);
  EXPECT_TRUE(one.checks.watertight());
  EXPECT_NEAR(one.checks.volume_m3, board, 0.01 * board);
  EXPECT_NEAR(exact_volume(one.mesh), board, 0.01 * board);
  EXPECT_LE(one.mesh.num_faces(), 64);  // the faces twice and walls, not a grid's surface
  const Eigen::AlignedBox3d box = bounds(one.mesh);
  EXPECT_NEAR(box.min().z(), 0.0, 1e-6);
  EXPECT_NEAR(box.max().z(), 0.002, 1e-6);

  // Two parts (the project stage makes two: no edge between them): each half
  // of the board, meeting in its middle; the parts together hold the board.
  done = complete_with_partition(faces, board_faces_as_parts(faces));
  ASSERT_TRUE(done.ok()) << done.status().message();
  for (const CompletedPart& p : done->parts) {
    SCOPED_TRACE("part " + std::to_string(p.part));
    EXPECT_EQ(p.backend, "shell");
    EXPECT_TRUE(p.ok);
    EXPECT_NEAR(p.checks.volume_m3, 0.5 * board, 0.01 * board);
    const Eigen::AlignedBox3d b = bounds(p.mesh);
    EXPECT_NEAR(p.part == 1 ? b.min().z() : b.max().z(), 0.001, 1e-6);  // the middle
  }
  EXPECT_NEAR(done->parts_volume_m3, board, 0.01 * board);
  for (const std::string& n : done->notes) EXPECT_EQ(n.rfind("volume check:", 0), std::string::npos) << n;
  bool said = false;
  for (const std::string& n : done->notes) said |= n.find("closed as shells of their measured thickness") != n.npos;
  EXPECT_TRUE(said);
}

TEST(ThinParts, AShellIsOnlyMadeWhereTheFacesBoundAThinSolid) {
  // A single sheet: nothing behind it.
  const Mesh sheet = test::mesh_from_geometry({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 3}});
  EXPECT_EQ(thin_part_shell(sheet, test::single_part(sheet, 1), 0).num_faces(), 0);
  // A closed cube: every ray meets the cube's own (single) piece.
  const Mesh cube = test::box_mesh({0, 0, 0}, {0.1f, 0.1f, 0.1f});
  EXPECT_EQ(thin_part_shell(cube, test::single_part(cube, 1), 0).num_faces(), 0);
  // A box split into its top face and the rest: the top is not thin (its
  // offset would reach halfway down a box as deep as it is wide).
  std::vector<Part> split(2);
  for (int f = 0; f < cube.num_faces(); ++f) {
    const Eigen::Vector3i& t = cube.triangles[static_cast<std::size_t>(f)];
    const bool top = cube.positions[static_cast<std::size_t>(t[0])].z() > 0.099f &&
                     cube.positions[static_cast<std::size_t>(t[1])].z() > 0.099f &&
                     cube.positions[static_cast<std::size_t>(t[2])].z() > 0.099f;
    split[top ? 1 : 0].label = 1;
    split[top ? 1 : 0].faces.push_back(f);
  }
  EXPECT_EQ(thin_part_shell(cube, split, 1).num_faces(), 0);
  // The edge-less board's top face: a shell, from its face to the middle.
  const Mesh faces = edgeless_board();
  const Mesh shell = thin_part_shell(faces, board_faces_as_parts(faces), 1);
  ASSERT_GT(shell.num_faces(), 0);
  EXPECT_NEAR(exact_volume(shell), 0.6 * 0.3 * 0.001, 1e-9);
  // Out of range: nothing.
  EXPECT_EQ(thin_part_shell(faces, board_faces_as_parts(faces), 7).num_faces(), 0);
}

// A pot (radii and height in metres) with its bottom ring missing: the wall
// is open along its lower edge, one part whose faces bound it on both sides.
struct Pot {
  float outer_radius = 0.05f, inner_radius = 0.045f, height = 0.1f;
  // The wall's volume: the 48-gon rings' area difference times the height.
  double wall_m3() const {
    const double r0 = outer_radius, r1 = inner_radius;
    return 0.5 * 48 * std::sin(2 * M_PI / 48) * (r0 * r0 - r1 * r1) * height;
  }
};

Mesh pot_without_bottom_ring(const Pot& pot) {
  const int n = 48;
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  for (float radius : {pot.outer_radius, pot.inner_radius})
    for (float z : {0.0f, pot.height})
      for (int i = 0; i < n; ++i) {
        const double a = 2 * M_PI * i / n;
        p.emplace_back(static_cast<float>(radius * std::cos(a)), static_cast<float>(radius * std::sin(a)), z);
      }
  // Rings: outer bottom 0, outer top n, inner bottom 2n, inner top 3n.
  for (unsigned i = 0; i < static_cast<unsigned>(n); ++i) {
    const unsigned j = (i + 1) % n, N = static_cast<unsigned>(n);
    t.push_back({i, j, j + N}), t.push_back({i, j + N, i + N});                                      // outer wall
    t.push_back({2 * N + i, 3 * N + j, 2 * N + j}), t.push_back({2 * N + i, 3 * N + i, 3 * N + j});  // inner wall
    t.push_back({N + i, N + j, 3 * N + j}), t.push_back({N + i, 3 * N + j, 3 * N + i});              // rim
  }
  return test::mesh_from_geometry(p, t);
}

// The pot's wall spans 5 cells of a grid `resolution` cells across: its
// middle lies 2.5 cells from the surface, beyond the default closing radius
// of 2, so the first pass floods the wall through its open edge and the
// second try, closing openings as wide as the wall is thick, keeps it.
void expect_closed_on_a_second_try(const Pot& shape, int resolution) {
  const Mesh pot = pot_without_bottom_ring(shape);
  const std::vector<Part> parts = test::single_part(pot, 1);
  const double wall = shape.wall_m3();
  // First pass only: the outside floods into the wall through its open edge.
  CompletionOptions first_pass_only;
  first_pass_only.resolve_thin_parts = false;
  const BackendSettings grid = {{"resolution", std::to_string(resolution)}};
  Result<Completion> done = complete_with_partition(pot, parts, first_pass_only, grid);
  ASSERT_TRUE(done.ok()) << done.status().message();
  EXPECT_NEAR(done->input_volume_m3, wall, 0.01 * wall);
  EXPECT_LT(done->parts[0].checks.volume_m3, 0.5 * wall);
  EXPECT_FALSE(done->parts[0].ok);

  // The second try closes openings as wide as the wall is thick.
  done = complete_with_partition(pot, parts, {}, grid);
  ASSERT_TRUE(done.ok()) << done.status().message();
  const CompletedPart& p = done->parts[0];
  EXPECT_EQ(p.backend, "partition");
  EXPECT_TRUE(p.ok);
  EXPECT_NEAR(p.checks.volume_m3, wall, CompletionOptions().volume_tolerance * wall);
  bool tried = false;
  for (const std::string& n : done->notes) tried |= n.find("tried again closing openings") != n.npos;
  EXPECT_TRUE(tried);
  bool widened = false;
  for (const std::string& n : done->notes) widened |= n.find("closing radius") != n.npos;
  EXPECT_TRUE(widened);
}

// A pot 100 mm wide and tall: a 5 mm wall on a 1 mm grid, the part about a
// million triangles (the main job's test; the sanitizer job runs the shorter
// pot below, scripts/sanitizers/release-only.txt).
TEST(ThinParts, AWallOpenAtItsEdgeIsClosedOnASecondTry) { expect_closed_on_a_second_try(Pot{}, 100); }

// The same wall 30 mm tall: a third of the grid and the triangles. (Not
// narrower: the volume estimate's rays along the axis meet the open edge
// unpaired, and a wall thicker than a tenth of the radius leaves too few
// paired to judge.)
TEST(ThinParts, AWallOpenAtItsEdgeIsClosedOnASecondTryInAShortPot) {
  expect_closed_on_a_second_try(Pot{0.05f, 0.045f, 0.03f}, 100);
}

}  // namespace
}  // namespace g2p
