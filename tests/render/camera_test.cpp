#include <gtest/gtest.h>

#include <cmath>

#include "g2p/io.h"
#include "g2p/render.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

TEST(Camera, LookAtIsARightHandedOpenCvFrame) {
  const Camera c = Camera::look_at({0, -5, 0}, {0, 0, 0}, {0, 0, 1}, 640, 480, 40);
  EXPECT_TRUE(c.validate().ok());
  EXPECT_TRUE(c.forward().isApprox(Eigen::Vector3d(0, 1, 0)));
  EXPECT_TRUE(c.rotation.col(0).isApprox(Eigen::Vector3d(1, 0, 0)));   // image right = world +X
  EXPECT_TRUE(c.rotation.col(1).isApprox(Eigen::Vector3d(0, 0, -1)));  // image down = world -Z
  EXPECT_NEAR(c.rotation.determinant(), 1.0, 1e-12);
  EXPECT_NEAR(c.fy, 240 / std::tan(20 * M_PI / 180), 1e-9);
  EXPECT_TRUE((c.world_to_camera() * c.camera_to_world()).isIdentity(1e-12));
}

TEST(Camera, RaysAndProjectionAreInverse) {
  for (bool ortho : {false, true}) {
    Camera c = Camera::look_at({1, -4, 2}, {0.1, 0.2, 0.3}, {0, 0, 1}, 320, 200, 55);
    if (ortho) c.orthographic = true, c.fx = c.fy = 90.0;
    for (double px : {0.5, 100.25, 319.5}) {
      for (double py : {0.5, 77.0, 199.5}) {
        Eigen::Vector3d o, d;
        c.ray(px, py, o, d);
        EXPECT_NEAR(d.norm(), 1.0, 1e-12);
        double depth = 0;
        const Eigen::Vector2d back = c.project(o + 2.5 * d, &depth);
        EXPECT_NEAR(back.x(), px, 1e-9) << (ortho ? "ortho" : "perspective");
        EXPECT_NEAR(back.y(), py, 1e-9);
        EXPECT_GT(depth, 0.0);
      }
    }
  }
}

TEST(Camera, ValidateNamesTheProblem) {
  Camera c;
  c.width = 0;
  EXPECT_NE(c.validate().message().find("camera size"), std::string::npos);
  c = Camera();
  c.fx = -1;
  EXPECT_NE(c.validate().message().find("focal"), std::string::npos);
  c = Camera();
  c.rotation(0, 0) = 2;
  EXPECT_NE(c.validate().message().find("rotation"), std::string::npos);
}

class Layouts : public testing::TestWithParam<std::tuple<ViewLayout, bool, int>> {};

TEST_P(Layouts, FrameTheWholeObjectAndLookAtItsCentre) {
  const auto [layout, ortho, count] = GetParam();
  const Mesh mesh = test::box_mesh({-0.3f, -0.1f, 0.f}, {0.5f, 0.2f, 1.2f});
  ViewOptions o;
  o.layout = layout;
  o.orthographic = ortho;
  o.num_views = count;
  o.width = 400;
  o.height = 300;
  Result<std::vector<Camera>> cams = make_views(mesh, o);
  ASSERT_TRUE(cams.ok()) << cams.status().to_string();
  ASSERT_EQ(static_cast<int>(cams->size()), count);
  const Eigen::Vector3d centre = bounds(mesh).center();
  for (const Camera& c : *cams) {
    ASSERT_TRUE(c.validate().ok());
    EXPECT_EQ(c.orthographic, ortho);
    // The principal ray goes through the centre.
    const Eigen::Vector2d p = c.project(centre);
    EXPECT_NEAR(p.x(), 200, 1e-6);
    EXPECT_NEAR(p.y(), 150, 1e-6);
    for (const Eigen::Vector3f& v : mesh.positions) {  // every corner inside the image
      double depth = 0;
      const Eigen::Vector2d q = c.project(v.cast<double>(), &depth);
      EXPECT_GT(depth, 0.0);
      EXPECT_GT(q.x(), 0.0);
      EXPECT_LT(q.x(), 400.0);
      EXPECT_GT(q.y(), 0.0);
      EXPECT_LT(q.y(), 300.0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(All, Layouts,
                         testing::Combine(testing::Values(ViewLayout::kSphere, ViewLayout::kFibonacci,
                                                          ViewLayout::kTurntable),
                                          testing::Bool(), testing::Values(1, 11, 24)));

TEST(ViewSet, DefaultIsElevenViewsWithTopBottomAndFront) {
  const Mesh mesh = test::box_mesh({-1, -1, -1}, {1, 1, 1});
  Result<std::vector<Camera>> cams = make_views(mesh);
  ASSERT_TRUE(cams.ok());
  ASSERT_EQ(cams->size(), 11u);
  EXPECT_TRUE((*cams)[0].forward().isApprox(-Eigen::Vector3d::UnitZ()));  // top view looks down
  EXPECT_TRUE((*cams)[1].forward().isApprox(Eigen::Vector3d::UnitZ()));   // bottom view looks up
  EXPECT_GT((*cams)[2].forward().y(), 0.5);                               // first ring view: from the front (-Y)
  EXPECT_EQ((*cams)[0].width, 512);
  // Directions are spread: no two cameras look within 30 degrees of each other.
  for (std::size_t i = 0; i < cams->size(); ++i)
    for (std::size_t j = i + 1; j < cams->size(); ++j)
      EXPECT_LT((*cams)[i].forward().dot((*cams)[j].forward()), std::cos(30 * M_PI / 180)) << i << " " << j;
}

TEST(ViewSet, RejectsBadOptions) {
  const Mesh mesh = test::box_mesh({0, 0, 0}, {1, 1, 1});
  ViewOptions o;
  o.num_views = 0;
  EXPECT_EQ(make_views(mesh, o).status().code(), StatusCode::kInvalidArgument);
  o = {};
  o.fov_y_deg = 180;
  EXPECT_EQ(make_views(mesh, o).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(make_views(Mesh{}).status().code(), StatusCode::kInvalidArgument);
}

TEST(CamerasJson, RoundTrip) {
  const Mesh mesh = test::box_mesh({0, 0, 0}, {1, 2, 3});
  ViewOptions o;
  o.orthographic = true;
  o.num_views = 5;
  const std::vector<Camera> cams = *make_views(mesh, o);
  Result<std::vector<Camera>> back = cameras_from_json(cameras_to_json(cams));
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  ASSERT_EQ(back->size(), cams.size());
  for (std::size_t i = 0; i < cams.size(); ++i) {
    EXPECT_TRUE((*back)[i].camera_to_world().isApprox(cams[i].camera_to_world(), 1e-12));
    EXPECT_TRUE((*back)[i].intrinsics().isApprox(cams[i].intrinsics(), 1e-12));
    EXPECT_TRUE((*back)[i].orthographic);
  }
  EXPECT_EQ(cameras_from_json("{}").status().code(), StatusCode::kParseError);
  EXPECT_NE(cameras_from_json(R"({"views": [{"width": 3}]})").status().message().find("views[0]"), std::string::npos);
  // A size that is not a whole number of pixels is refused (a float such as 2e107 used to be cast to int).
  for (const char* size : {"2.2e107", "640.5", "0", "-3", "99999"}) {
    const std::string text = std::string(R"({"views": [{"width": )") + size + R"(, "height": 480}]})";
    Result<std::vector<Camera>> bad = cameras_from_json(text);
    EXPECT_EQ(bad.status().code(), StatusCode::kParseError) << size;
    EXPECT_NE(bad.status().message().find("'width' must be a whole number of pixels"), std::string::npos)
        << bad.status().message();
  }
}

// camera_space_normals on a real asset: every surface the camera sees faces
// it (against the pixel's ray in the camera's frame), the vectors stay unit length, the
// background is zero, and a view without geometry buffers has none.
TEST(CameraSpaceNormals, FaceTheCameraOnTheChair) {
  Result<Model> chair = load_model(test::source_path("../shared/assets/SheenChair/SheenChair.glb"));
  ASSERT_TRUE(chair.ok()) << chair.status().to_string();
  Result<std::vector<Camera>> cameras = make_views(chair->mesh, {3, ViewLayout::kSphere, 96, 96});
  ASSERT_TRUE(cameras.ok());
  Result<std::unique_ptr<Renderer>> renderer = renderer_registry().create("embree");
  ASSERT_TRUE(renderer.ok() && (*renderer)->set_model(*chair).ok());
  for (const Camera& camera : *cameras) {
    Result<View> view = (*renderer)->render(camera);
    ASSERT_TRUE(view.ok());
    const ImageF n = camera_space_normals(*view);
    ASSERT_EQ(n.width(), 96);
    ASSERT_EQ(n.channels(), 3);
    int object = 0;
    for (int y = 0; y < 96; ++y)
      for (int x = 0; x < 96; ++x) {
        const Eigen::Vector3f v(n.at(x, y, 0), n.at(x, y, 1), n.at(x, y, 2));
        if (view->face_id.at(x, y) < 0) {
          ASSERT_EQ(v.norm(), 0.f);
          continue;
        }
        ++object;
        ASSERT_NEAR(v.norm(), 1.f, 1e-4f);
        // Facing the viewer: against the pixel's ray, in the camera's frame.
        Eigen::Vector3d origin, direction;
        camera.ray(x + 0.5, y + 0.5, origin, direction);
        const Eigen::Vector3f ray = (camera.rotation.transpose() * direction).cast<float>();
        ASSERT_LT(v.dot(ray), 1e-4f) << "pixel " << x << "," << y;
        // The same vector as the world-space buffer, turned by the camera's rotation.
        const Eigen::Vector3f world(view->normal.at(x, y, 0), view->normal.at(x, y, 1), view->normal.at(x, y, 2));
        ASSERT_NEAR((camera.rotation.cast<float>() * v - world).norm(), 0.f, 1e-5f);
      }
    EXPECT_GT(object, 500);
  }
  RenderOptions bare;
  bare.geometry_buffers = false;
  Result<View> view = (*renderer)->render(cameras->front(), bare);
  ASSERT_TRUE(view.ok());
  EXPECT_TRUE(camera_space_normals(*view).empty());
}

}  // namespace
}  // namespace g2p
