#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "g2p/io.h"
#include "g2p/render.h"
#include "support/test_data.h"

namespace g2p {
namespace {

TEST(FaceIdEncoding, RoundTripsEveryRepresentableId) {
  ImageI32 ids(5, 2, 1);
  const std::int32_t values[] = {-1, 0, 1, 255, 256, 65535, 65536, 123456, (1 << 24) - 2, 7};
  for (int i = 0; i < 10; ++i) ids.data()[i] = values[i];
  Result<ImageU8> encoded = encode_face_ids(ids);
  ASSERT_TRUE(encoded.ok());
  EXPECT_EQ(encoded->at(0, 0, 0), 0);  // background is black
  Result<ImageI32> decoded = decode_face_ids(*encoded);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(*decoded, ids);
  ids.at(0, 0) = 1 << 24;
  EXPECT_EQ(encode_face_ids(ids).status().code(), StatusCode::kUnsupported);
}

TEST(WriteViews, WritesImagesCamerasAndContactSheet) {
  Result<Model> model = load_model(test::source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(model.ok());
  auto renderer = std::move(*renderer_registry().create("embree"));
  ViewOptions vo;
  vo.num_views = 3;
  vo.width = 80;
  vo.height = 60;
  Result<std::vector<View>> views = render_views(*renderer, *model, *make_views(model->mesh, vo));
  ASSERT_TRUE(views.ok());
  const std::string dir = test::scratch_dir("WriteViews.All") + "/out/nested";  // created on demand
  ViewFileOptions fo;
  fo.buffers = true;
  ASSERT_TRUE(write_views(dir, *views, fo).ok());
  for (const char* f :
       {"view_00_rgb.png", "view_02_faceid.png", "view_01_depth.npy", "view_01_normal.png", "view_01_basecolor.png",
        "view_01_metallicroughness.png", "view_01_transmission.png", "cameras.json", "contact_sheet.png"})
    EXPECT_TRUE(std::filesystem::is_regular_file(dir + "/" + f)) << f;
  // Nothing temporary is left behind.
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp", 0), std::string::npos) << e.path();

  // The face-ID PNG decodes to exactly the buffer.
  Result<ImageU8> png = read_image(dir + "/view_02_faceid.png");
  ASSERT_TRUE(png.ok());
  EXPECT_EQ(*decode_face_ids(*png), (*views)[2].face_id);
  // The RGB PNG is the image.
  Result<ImageU8> rgb = read_image(dir + "/view_00_rgb.png");
  ASSERT_TRUE(rgb.ok());
  EXPECT_EQ(rgb->at(40, 30, 1), (*views)[0].rgb.at(40, 30, 1));

  // cameras.json holds the same cameras.
  Result<std::vector<Camera>> cams = cameras_from_json(test::read_file(dir + "/cameras.json"));
  ASSERT_TRUE(cams.ok());
  ASSERT_EQ(cams->size(), 3u);
  EXPECT_TRUE((*cams)[1].camera_to_world().isApprox((*views)[1].camera.camera_to_world(), 1e-12));

  // depth.npy: NumPy header with the shape, then little-endian float32 rows.
  const std::string npy = test::read_file(dir + "/view_01_depth.npy");
  ASSERT_EQ(npy.compare(0, 6, "\x93NUMPY"), 0);
  const std::size_t header = static_cast<unsigned char>(npy[8]) | (static_cast<unsigned char>(npy[9]) << 8);
  EXPECT_NE(npy.find("'shape': (60, 80)"), std::string::npos);
  ASSERT_EQ(npy.size(), 10 + header + 80 * 60 * 4);
  float value = 0;
  std::memcpy(&value, npy.data() + 10 + header + 4 * (30 * 80 + 40), 4);
  EXPECT_EQ(value, (*views)[1].depth.at(40, 30));

  Result<ImageU8> sheet = read_image(dir + "/contact_sheet.png");
  ASSERT_TRUE(sheet.ok());
  EXPECT_EQ(sheet->width(), 3 * (256 + 4) + 4);
}

TEST(WriteViews, RefusesAFileWhereTheFolderShouldBe) {
  const std::string dir = test::scratch_dir("WriteViews.Refuse");
  test::write_file(dir + "/taken", "x");
  View v;
  v.face_id = ImageI32(4, 4, 1, -1);
  Status s = write_views(dir + "/taken", {v});
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(test::read_file(dir + "/taken"), "x");  // untouched
  EXPECT_EQ(write_views(dir + "/empty", {}).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace g2p
