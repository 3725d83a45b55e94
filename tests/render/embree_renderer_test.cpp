// The Embree renderer against independent references: brute-force ray
// casting for the face-ID buffer, full coverage of convex meshes, textures at
// known pixels, masks and transparency.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "g2p/io.h"
#include "g2p/render.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

std::unique_ptr<Renderer> embree() {
  Result<std::unique_ptr<Renderer>> r = renderer_registry().create("embree");
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return std::move(*r);
}

// Möller-Trumbore, two-sided; returns t or +inf. `slack` widens the triangle
// by that much in barycentric terms.
double intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 const Eigen::Vector3d& c, double slack = 1e-7) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-18) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d s = o - a;
  const double u = s.dot(p) / det;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) / det;
  const double t = e2.dot(q) / det;
  if (u < -slack || v < -slack || u + v > 1 + slack || t <= 0) return std::numeric_limits<double>::infinity();
  return t;
}

// Compares the face-ID buffer with brute-force casting on every `stride`-th
// pixel. A pixel agrees when the ray, by brute force, hits Embree's face (with
// a 0.1% barycentric slack for rays through shared edges) at the nearest
// distance found over all faces.
void expect_face_ids_match_brute_force(const Model& model, int views, int resolution, int stride) {
  auto renderer = embree();
  ASSERT_TRUE(renderer->set_model(model).ok());
  ViewOptions vo;
  vo.num_views = views;
  vo.width = vo.height = resolution;
  const std::vector<Camera> cameras = *make_views(model.mesh, vo);
  RenderOptions ro;
  ro.shade = ro.material_buffers = ro.geometry_buffers = false;
  const Mesh& mesh = model.mesh;
  const double scale = bounds(mesh).diagonal().norm();
  int checked = 0, hits = 0, disagreements = 0;
  for (const Camera& cam : cameras) {
    Result<View> view = renderer->render(cam, ro);
    ASSERT_TRUE(view.ok()) << view.status().to_string();
    for (int y = stride / 2; y < resolution; y += stride) {
      for (int x = stride / 2; x < resolution; x += stride) {
        Eigen::Vector3d o, d;
        cam.ray(x + 0.5, y + 0.5, o, d);
        double best = std::numeric_limits<double>::infinity();
        for (int f = 0; f < mesh.num_faces(); ++f) {
          const Eigen::Vector3i& t = mesh.triangles[f];
          best = std::min(best, intersect(o, d, mesh.positions[t[0]].cast<double>(),
                                          mesh.positions[t[1]].cast<double>(), mesh.positions[t[2]].cast<double>()));
        }
        const int id = view->face_id.at(x, y);
        ++checked;
        hits += id >= 0;
        bool agree;
        if (id < 0) {
          agree = std::isinf(best);
        } else {
          const Eigen::Vector3i& t = mesh.triangles[id];
          const double t_face =
              intersect(o, d, mesh.positions[t[0]].cast<double>(), mesh.positions[t[1]].cast<double>(),
                        mesh.positions[t[2]].cast<double>(), 1e-3);
          agree = std::isfinite(t_face) && std::abs(t_face - best) <= 1e-5 * scale;
        }
        disagreements += !agree;
      }
    }
  }
  EXPECT_GT(hits, checked / 25) << "the object should fill part of the views";
  // Rays that graze an edge or a silhouette may legitimately differ.
  EXPECT_LE(disagreements, checked / 500) << disagreements << " of " << checked << " sampled pixels disagree";
}

TEST(EmbreeRenderer, FaceIdsMatchBruteForceOnSheenChair) {
  ImportOptions io;
  io.load_textures = false;
  Result<Model> model = load_model(test::asset_path("SheenChair"), io);
  ASSERT_TRUE(model.ok());
  expect_face_ids_match_brute_force(*model, 3, 192, 4);
}

TEST(EmbreeRenderer, FaceIdsMatchBruteForceOnGeneratedHammer) {
  const std::string dir = test::scratch_dir("EmbreeRenderer.Hammer");
  test::make_hammer().write(dir + "/hammer.glb");
  Result<Model> model = load_model(dir + "/hammer.glb");
  ASSERT_TRUE(model.ok());
  expect_face_ids_match_brute_force(*model, 11, 128, 2);
}

// An icosphere: every face of a closed convex mesh faces some view.
Mesh icosphere(int subdivisions, const Eigen::Vector3f& radii) {
  const float p = (1.f + std::sqrt(5.f)) / 2.f;
  std::vector<Eigen::Vector3f> v = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                                    {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  std::vector<Eigen::Vector3i> f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                    {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& x : v) x.normalize();
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& t : f) {
      const int a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      next.insert(next.end(), {{t[0], a, c}, {t[1], b, a}, {t[2], c, b}, {a, b, c}});
    }
    f = next;
  }
  Mesh m;
  for (const auto& x : v) m.positions.push_back(x.cwiseProduct(radii));
  m.triangles = f;
  return m;
}

TEST(EmbreeRenderer, EveryFaceOfAConvexMeshIsSeenByTheDefaultViews) {
  for (const Eigen::Vector3f radii : {Eigen::Vector3f(1, 1, 1), Eigen::Vector3f(1.0f, 0.4f, 0.15f)}) {
    Model model;
    model.mesh = icosphere(3, radii);
    auto renderer = embree();
    RenderOptions ro;
    ro.shade = ro.material_buffers = ro.geometry_buffers = false;
    Result<std::vector<View>> views = render_views(*renderer, model, *make_views(model.mesh), ro);
    ASSERT_TRUE(views.ok()) << views.status().to_string();
    std::set<int> seen;
    for (const View& v : *views)
      for (std::size_t i = 0; i < v.face_id.size(); ++i)
        if (v.face_id.data()[i] >= 0) seen.insert(v.face_id.data()[i]);
    EXPECT_EQ(static_cast<int>(seen.size()), model.mesh.num_faces()) << "radii " << radii.transpose();
  }
}

// A 64x64 texture with four coloured quadrants: red top-left, green top-right,
// blue bottom-left, white bottom-right.
std::string quadrant_png(std::uint8_t alpha_left = 255) {
  return test::png_bytes(64, 64, [&](int x, int y) -> std::array<std::uint8_t, 4> {
    const std::uint8_t a = x < 32 ? alpha_left : 255;
    if (y < 32) return x < 32 ? std::array<std::uint8_t, 4>{255, 0, 0, a} : std::array<std::uint8_t, 4>{0, 255, 0, a};
    return x < 32 ? std::array<std::uint8_t, 4>{0, 0, 255, a} : std::array<std::uint8_t, 4>{255, 255, 255, a};
  });
}

// Front view (from -Y, +Z up) of the glTF plane z = 0 seen orthographically:
// world x -> image right, world z (glTF y) -> image up.
Camera front_camera(int size, double half_extent) {
  Camera c = Camera::look_at({0, -5, 0}, {0, 0, 0}, {0, 0, 1}, size, size, 40);
  c.orthographic = true;
  c.fx = c.fy = 0.5 * size / half_extent;
  return c;
}

Model load_built(const test::GltfBuilder& g, const std::string& name) {
  const std::string dir = test::scratch_dir(name);
  g.write(dir + "/model.glb");
  Result<Model> model = load_model(dir + "/model.glb");
  EXPECT_TRUE(model.ok()) << model.status().to_string();
  return model.ok() ? std::move(*model) : Model{};
}

TEST(EmbreeRenderer, TexturedQuadShowsItsTextureAtTheExpectedPixels) {
  test::GltfBuilder g;
  const int tex = g.add_texture(quadrant_png());
  const int plain = g.add_material("plain", {1, 1, 1, 1}, 0.f, 1.f, tex);
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  std::vector<Eigen::Vector2f> uv;
  test::quad_geometry(-1, -1, 1, 1, 0, p, t, uv);
  g.add_node(g.add_mesh("plain", p, t, plain, uv));
  Model model = load_built(g, "EmbreeRenderer.TexturedQuad");
  ASSERT_EQ(model.mesh.num_faces(), 2);

  auto renderer = embree();
  ASSERT_TRUE(renderer->set_model(model).ok());
  Result<View> view = renderer->render(front_camera(64, 1.0));
  ASSERT_TRUE(view.ok()) << view.status().to_string();
  // Quadrant centres: the material buffer holds the linear texture colour.
  const struct {
    int x, y;
    Eigen::Vector3f rgb;
  } expected[] = {{16, 16, {1, 0, 0}}, {48, 16, {0, 1, 0}}, {16, 48, {0, 0, 1}}, {48, 48, {1, 1, 1}}};
  for (const auto& e : expected) {
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(view->base_color.at(e.x, e.y, c), e.rgb[c], 1e-3) << "pixel " << e.x << "," << e.y;
    // In the shaded image the texture's colour dominates.
    const std::uint8_t* px = view->rgb.pixel(e.x, e.y);
    if (e.rgb.sum() == 1.f) {
      int dominant = 0;
      for (int c = 1; c < 3; ++c)
        if (px[c] > px[dominant]) dominant = c;
      EXPECT_EQ(e.rgb[dominant], 1.f) << "pixel " << e.x << "," << e.y;
    }
    EXPECT_GE(view->face_id.at(e.x, e.y), 0);
  }

  // Shifted by half the texture (KHR_texture_transform) and repeating, the
  // left half shows what was on the right.
  test::GltfBuilder g2;
  const int tex2 = g2.add_texture(quadrant_png());
  const int m2 = g2.add_material("shifted", {1, 1, 1, 1}, 0.f, 1.f, tex2,
                                 R"({"extensions": {"KHR_texture_transform": {"offset": [0.5, 0]}}})");
  g2.add_node(g2.add_mesh("shifted", p, t, m2, uv));
  Model moved = load_built(g2, "EmbreeRenderer.TexturedQuadShifted");
  ASSERT_TRUE(renderer->set_model(moved).ok());
  Result<View> shifted_view = renderer->render(front_camera(64, 1.0));
  ASSERT_TRUE(shifted_view.ok());
  EXPECT_NEAR(shifted_view->base_color.at(16, 16, 1), 1.f, 1e-3);  // green now top-left
  EXPECT_NEAR(shifted_view->base_color.at(48, 16, 0), 1.f, 1e-3);  // red wrapped round to the top-right
  EXPECT_NEAR(shifted_view->base_color.at(48, 16, 1), 0.f, 1e-3);
}

// Two squares in the file's z = 0 plane (Y up, so facing the front camera
// after import): x in [-1, 0] red, x in [0, 1] blue, as 8-bit sRGB vertex
// colours, with no texture (PLY has no materials: assimp's default one).
constexpr const char* kTwoColourPly = R"(ply
format ascii 1.0
element vertex 8
property float x
property float y
property float z
property uchar red
property uchar green
property uchar blue
element face 4
property list uchar int vertex_indices
end_header
-1 -1 0 220 40 40
0 -1 0 220 40 40
0 1 0 220 40 40
-1 1 0 220 40 40
0 -1 0 40 40 220
1 -1 0 40 40 220
1 1 0 40 40 220
0 1 0 40 40 220
3 0 1 2
3 0 2 3
3 4 5 6
3 4 6 7
)";

TEST(EmbreeRenderer, VertexColoursShowOnAMaterialWithoutTexture) {
  const std::string dir = test::scratch_dir("EmbreeRenderer.VertexColours");
  test::write_file(dir + "/halves.ply", kTwoColourPly);
  Result<Model> model = load_model(dir + "/halves.ply");  // the child-process reader, the default
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  ASSERT_TRUE(model->mesh.has_colors());
  for (const SourceMaterial& m : model->materials) ASSERT_TRUE(m.base_color_texture.empty());

  auto renderer = embree();
  ASSERT_TRUE(renderer->set_model(*model).ok());
  Result<View> view = renderer->render(front_camera(64, 1.0));
  ASSERT_TRUE(view.ok()) << view.status().to_string();
  const int left_x = 16, right_x = 48, y = 32;
  ASSERT_GE(view->face_id.at(left_x, y), 0);
  ASSERT_GE(view->face_id.at(right_x, y), 0);
  // The base colour buffer is the material's base colour times the vertex colour.
  for (const int x : {left_x, right_x}) {
    const int f = view->face_id.at(x, y);
    const int m = model->mesh.face_source[static_cast<std::size_t>(f)].material;
    const Eigen::Vector3f factor =
        m >= 0 ? Eigen::Vector3f(model->materials[static_cast<std::size_t>(m)].base_color.head<3>())
               : Eigen::Vector3f::Ones();
    const Eigen::Vector4f& vertex = model->mesh.colors[static_cast<std::size_t>(model->mesh.triangles[f][0])];
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(view->base_color.at(x, y, c), factor[c] * vertex[c], 1e-4) << "pixel " << x << "," << y;
  }
  // Red on the left, blue on the right, in the material buffer and in the shaded image.
  EXPECT_GT(view->base_color.at(left_x, y, 0), 5.f * view->base_color.at(left_x, y, 2));
  EXPECT_GT(view->base_color.at(right_x, y, 2), 5.f * view->base_color.at(right_x, y, 0));
  const std::uint8_t* left = view->rgb.pixel(left_x, y);
  const std::uint8_t* right = view->rgb.pixel(right_x, y);
  EXPECT_GT(left[0], left[2] + 60) << "left half should look red";
  EXPECT_GT(right[2], right[0] + 60) << "right half should look blue";

  // Without its colours the same mesh renders the two halves alike.
  Model plain = *model;
  plain.mesh.colors.clear();
  ASSERT_TRUE(renderer->set_model(plain).ok());
  Result<View> grey = renderer->render(front_camera(64, 1.0));
  ASSERT_TRUE(grey.ok());
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(grey->base_color.at(left_x, y, c), grey->base_color.at(right_x, y, c), 1e-6);
}

TEST(EmbreeRenderer, AlphaMaskCutsOutAndTransmissionShowsWhatIsBehind) {
  test::GltfBuilder g;
  const int tex = g.add_texture(quadrant_png(/*alpha_left=*/0));
  const int masked = g.add_material("masked", {1, 1, 1, 1}, 0.f, 1.f, tex, "{}", R"({"alphaMode": "MASK"})");
  const int glass = g.add_material("glass", {1, 1, 1, 1}, 0.f, 0.05f, -1, "{}",
                                   R"({"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}}})");
  const int red = g.add_material("red", {1, 0, 0, 1}, 0.f, 1.f);
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  std::vector<Eigen::Vector2f> uv;
  test::quad_geometry(-1, 0, 1, 1, 0.5f, p, t, uv);  // top half: masked texture, nearest the camera
  g.add_node(g.add_mesh("masked", p, t, masked, uv));
  p.clear(), t.clear(), uv.clear();
  test::quad_geometry(-1, -1, 1, 0, 0.5f, p, t, uv);  // bottom half: glass
  g.add_node(g.add_mesh("glass", p, t, glass, uv));
  p.clear(), t.clear(), uv.clear();
  test::quad_geometry(-1, -1, 1, 1, -0.5f, p, t, uv);  // behind both: red
  g.add_node(g.add_mesh("red", p, t, red, uv));
  Model model = load_built(g, "EmbreeRenderer.MaskAndGlass");

  auto renderer = embree();
  ASSERT_TRUE(renderer->set_model(model).ok());
  Result<View> view = renderer->render(front_camera(64, 1.0));
  ASSERT_TRUE(view.ok());
  auto material_at = [&](int x, int y) {
    const int f = view->face_id.at(x, y);
    return f < 0 ? std::string("none") : model.materials[model.mesh.face_source[f].material].name;
  };
  EXPECT_EQ(material_at(16, 8), "red");     // masked-out texels are not surfaces
  EXPECT_EQ(material_at(48, 8), "masked");  // opaque texels are
  EXPECT_EQ(material_at(16, 48), "glass");  // glass is the first surface...
  const std::uint8_t* through = view->rgb.pixel(16, 48);
  EXPECT_GT(through[0], through[1] + 60) << "...but the red quad shows through it";
  EXPECT_FLOAT_EQ(view->transmission.at(16, 48), 1.f);
}

TEST(EmbreeRenderer, DeterministicAndBuffersConsistent) {
  Result<Model> model = load_model(test::asset_path("GlassHurricaneCandleHolder"));
  ASSERT_TRUE(model.ok());
  auto renderer = embree();
  ASSERT_TRUE(renderer->set_model(*model).ok());
  ViewOptions vo;
  vo.num_views = 2;
  vo.width = vo.height = 96;
  const Camera cam = (*make_views(model->mesh, vo))[1];
  Result<View> a = renderer->render(cam), b = renderer->render(cam);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->rgb, b->rgb);
  EXPECT_EQ(a->face_id, b->face_id);
  for (int y = 0; y < 96; ++y) {
    for (int x = 0; x < 96; ++x) {
      const bool hit = a->face_id.at(x, y) >= 0;
      EXPECT_EQ(std::isfinite(a->depth.at(x, y)), hit);
      if (!hit) continue;
      // The depth buffer puts the pixel's ray on the plane of the face it names.
      Eigen::Vector3d o, d;
      cam.ray(x + 0.5, y + 0.5, o, d);
      const Eigen::Vector3d point = o + d * (a->depth.at(x, y) / d.dot(cam.forward()));
      const Eigen::Vector3i& t = model->mesh.triangles[a->face_id.at(x, y)];
      const Eigen::Vector3d p0 = model->mesh.positions[t[0]].cast<double>();
      EXPECT_NEAR(face_normal(model->mesh, a->face_id.at(x, y)).dot(point - p0), 0.0, 1e-4);
      const Eigen::Vector3f n(a->normal.at(x, y, 0), a->normal.at(x, y, 1), a->normal.at(x, y, 2));
      EXPECT_NEAR(n.norm(), 1.f, 1e-4f);
      EXPECT_LE(n.cast<double>().dot(d), 1e-6);  // faces the camera
    }
  }
}

// RenderOptions::lights: empty is the studio set; one light from the camera's
// left brightens the surfaces that face left, its mirror image those that face
// right; a bad light is an error naming it.
TEST(EmbreeRenderer, LightsDefaultToTheStudioSetAndCanBeReplaced) {
  Result<Model> model = load_model(test::asset_path("Avocado"));
  ASSERT_TRUE(model.ok());
  auto renderer = embree();
  ASSERT_TRUE(renderer->set_model(*model).ok());
  ViewOptions vo;
  vo.num_views = 1;
  vo.width = vo.height = 128;
  const Camera cam = (*make_views(model->mesh, vo))[0];
  RenderOptions studio;
  studio.lights = studio_lights();
  Result<View> by_default = renderer->render(cam), explicit_studio = renderer->render(cam, studio);
  ASSERT_TRUE(by_default.ok() && explicit_studio.ok());
  EXPECT_EQ(by_default->rgb, explicit_studio->rgb);

  // Mean brightness of the pixels facing the camera's left and right.
  auto left_over_right = [&](const Eigen::Vector3f& towards_light) {
    RenderOptions one;
    one.lights = {CameraLight{towards_light, 3.f}};
    Result<View> v = renderer->render(cam, one);
    EXPECT_TRUE(v.ok());
    double sum[2] = {0, 0};
    int count[2] = {0, 0};
    const Eigen::Matrix3f to_camera = cam.rotation.cast<float>().transpose();
    for (int y = 0; y < 128; ++y)
      for (int x = 0; x < 128; ++x) {
        if (v->face_id.at(x, y) < 0) continue;
        const Eigen::Vector3f n =
            to_camera * Eigen::Vector3f(v->normal.at(x, y, 0), v->normal.at(x, y, 1), v->normal.at(x, y, 2));
        if (std::abs(n.x()) < 0.5f) continue;
        const int side = n.x() < 0 ? 0 : 1;
        sum[side] += v->rgb.at(x, y, 0) + v->rgb.at(x, y, 1) + v->rgb.at(x, y, 2);
        ++count[side];
      }
    EXPECT_GT(count[0], 50);
    EXPECT_GT(count[1], 50);
    return (sum[0] / std::max(count[0], 1)) / (sum[1] / std::max(count[1], 1) + 1e-9);
  };
  const double from_left = left_over_right({-1.f, 0.f, -0.3f}), from_right = left_over_right({1.f, 0.f, -0.3f});
  std::printf("left/right brightness: %.2f lit from the left, %.2f from the right\n", from_left, from_right);
  EXPECT_GT(from_left, 1.25);  // measured 1.58: the ambient terms light both sides
  EXPECT_LT(from_right, 0.8);  // measured 0.45
  EXPECT_GT(from_left, 2 * from_right);

  for (const CameraLight& bad : {CameraLight{Eigen::Vector3f::Zero(), 1.f}, CameraLight{Eigen::Vector3f::UnitX(), -1.f},
                                 CameraLight{Eigen::Vector3f::UnitX(), std::nanf("")}}) {
    RenderOptions o;
    o.lights = {studio_lights()[0], bad};
    Result<View> v = renderer->render(cam, o);
    EXPECT_EQ(v.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(v.status().message().find("lights[1]"), std::string::npos) << v.status().to_string();
  }
}

TEST(EmbreeRenderer, RenderIntoReusesAViewWithoutChangingTheResult) {
  Result<Model> model = load_model(test::asset_path("SheenChair"));
  ASSERT_TRUE(model.ok());
  auto renderer = embree();
  ASSERT_TRUE(renderer->set_model(*model).ok());
  ViewOptions vo;
  vo.width = 80;
  vo.height = 64;
  const std::vector<Camera> cams = *make_views(model->mesh, vo);
  View reused;
  for (const Camera& cam : {cams[3], cams[0]}) {
    ASSERT_TRUE(renderer->render_into(cam, {}, reused).ok());
    Result<View> fresh = renderer->render(cam);
    ASSERT_TRUE(fresh.ok());
    EXPECT_EQ(reused.rgb, fresh->rgb);
    EXPECT_EQ(reused.face_id, fresh->face_id);
    EXPECT_EQ(reused.base_color, fresh->base_color);
    EXPECT_EQ(reused.depth, fresh->depth);
  }
  RenderOptions ids_only;
  ids_only.shade = ids_only.material_buffers = ids_only.geometry_buffers = false;
  ASSERT_TRUE(renderer->render_into(cams[1], ids_only, reused).ok());
  EXPECT_TRUE(reused.rgb.empty());  // buffers not asked for are emptied, never stale
  EXPECT_TRUE(reused.depth.empty());
  EXPECT_TRUE(reused.base_color.empty());
  EXPECT_EQ(reused.face_id.width(), 80);
}

TEST(EmbreeRenderer, ErrorsAreReported) {
  auto renderer = embree();
  EXPECT_EQ(renderer->render(Camera()).status().code(), StatusCode::kInvalidArgument);  // no model yet
  EXPECT_EQ(renderer->set_model(Model()).code(), StatusCode::kInvalidArgument);         // empty mesh
  Model bad;
  bad.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  bad.mesh.triangles = {{0, 1, 5}};
  EXPECT_NE(renderer->set_model(bad).message().find("index 5 out of range"), std::string::npos);
  Result<std::unique_ptr<Renderer>> none = renderer_registry().create("raytracer9000");
  EXPECT_EQ(none.status().code(), StatusCode::kNotFound);
  EXPECT_NE(none.status().message().find("embree"), std::string::npos);  // lists the known ones
}

}  // namespace
}  // namespace g2p
