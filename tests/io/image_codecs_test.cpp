// The image codecs (libpng, libjpeg-turbo, libwebp, libtiff, BMP): every
// texture of the shared assets and of Debian's assimp-testmodels decodes to
// the very pixels OpenCV's imgcodecs gave (what libg2p used before, linked
// here only), each format round-trips, and damaged or foreign data is named.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <nlohmann/json.hpp>

#include "g2p/io.h"
#include "support/test_data.h"

namespace g2p {
namespace {

// What libg2p made of an image before: OpenCV's decoder, IMREAD_UNCHANGED,
// then 16 bits scaled by 1/257, grey-with-alpha as grey, all to RGBA.
ImageU8 decode_with_opencv(const std::string& bytes) {
  const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data()));
  cv::Mat m = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  if (m.empty()) return ImageU8();
  if (m.depth() == CV_16U) m.convertTo(m, CV_8U, 1.0 / 257.0);
  if (m.channels() == 2) cv::extractChannel(m, m, 0);
  ImageU8 out(m.cols, m.rows, 4);
  cv::Mat rgba(m.rows, m.cols, CV_8UC4, out.data());
  cv::cvtColor(m, rgba,
               m.channels() == 1   ? cv::COLOR_GRAY2RGBA
               : m.channels() == 3 ? cv::COLOR_BGR2RGBA
                                   : cv::COLOR_BGRA2RGBA);
  return out;
}

// libg2p's decode of `bytes`, through a file (read_image).
Result<ImageU8> decode(const std::string& bytes, const std::string& dir, const std::string& name) {
  const std::string path = dir + "/" + name;
  test::write_file(path, bytes);
  return read_image(path);
}

// The images a GLB embeds, as bytes with their MIME type.
std::vector<std::pair<std::string, std::string>> glb_images(const std::string& path) {
  const std::string glb = test::read_file(path);
  std::vector<std::pair<std::string, std::string>> images;
  std::uint32_t json_length = 0;
  std::memcpy(&json_length, glb.data() + 12, 4);
  const nlohmann::json doc = nlohmann::json::parse(glb.substr(20, json_length));
  const std::size_t bin = 20 + json_length + 8;
  for (const nlohmann::json& image : doc.value("images", nlohmann::json::array())) {
    if (!image.contains("bufferView")) continue;
    const nlohmann::json& view = doc["bufferViews"][image["bufferView"].get<std::size_t>()];
    images.emplace_back(
        glb.substr(bin + view.value("byteOffset", std::size_t{0}), view["byteLength"].get<std::size_t>()),
        image.value("mimeType", std::string()));
  }
  return images;
}

void expect_same_pixels(const ImageU8& ours, const ImageU8& theirs, const std::string& what) {
  ASSERT_FALSE(theirs.empty()) << what << ": OpenCV could not decode it";
  ASSERT_EQ(ours.width(), theirs.width()) << what;
  ASSERT_EQ(ours.height(), theirs.height()) << what;
  ASSERT_EQ(ours.channels(), 4) << what;
  std::size_t differ = 0;
  for (std::size_t i = 0; i < ours.size(); ++i) differ += ours.data()[i] != theirs.data()[i] ? 1 : 0;
  EXPECT_EQ(differ, 0u) << what << ": " << differ << " of " << ours.size() << " values differ";
}

TEST(ImageCodecs, EveryTextureOfTheSharedAssetsDecodesAsOpenCvDecodedIt) {
  const std::string dir = test::scratch_dir("ImageCodecs.SharedAssets");
  int png = 0;
  for (const char* asset : {"SheenChair", "GlamVelvetSofa", "WaterBottle", "Avocado", "GlassHurricaneCandleHolder"}) {
    int i = 0;
    for (const auto& [bytes, mime] : glb_images(test::asset_path(asset))) {
      const std::string what = std::string(asset) + " image " + std::to_string(i++) + " (" + mime + ")";
      Result<ImageU8> ours = decode(bytes, dir, "texture");
      ASSERT_TRUE(ours.ok()) << what << ": " << ours.status().to_string();
      expect_same_pixels(*ours, decode_with_opencv(bytes), what);
      png += mime == "image/png" ? 1 : 0;
    }
  }
  EXPECT_GE(png, 5);  // the shared assets' textures are PNGs; JPEGs come from the assimp models
}

TEST(ImageCodecs, EveryImageOfTheAssimpTestModelsDecodesAsOpenCvDecodedIt) {
  const std::string root = test::assimp_model("");
  if (!std::filesystem::exists(root)) GTEST_SKIP() << root << " is absent (Debian's assimp-testmodels)";
  const std::string dir = test::scratch_dir("ImageCodecs.Assimp");
  std::map<std::string, int> seen;
  for (const auto& e : std::filesystem::recursive_directory_iterator(root)) {
    std::string ext = e.path().extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (!e.is_regular_file() || (ext != ".png" && ext != ".jpg" && ext != ".jpeg" && ext != ".bmp")) continue;
    const std::string bytes = test::read_file(e.path().string());
    const ImageU8 theirs = decode_with_opencv(bytes);
    Result<ImageU8> ours = read_image(e.path().string());
    if (theirs.empty()) {  // damaged on purpose: both refuse it
      EXPECT_FALSE(ours.ok()) << e.path();
      continue;
    }
    ASSERT_TRUE(ours.ok()) << e.path() << ": " << ours.status().to_string();
    expect_same_pixels(*ours, theirs, e.path().string());
    ++seen[ext];
  }
  EXPECT_GE(seen[".png"], 20);
  EXPECT_GE(seen[".jpg"], 10);
  EXPECT_GE(seen[".bmp"], 2);
}

// An image with every value used, `channels` deep; `smooth`: gradients
// instead (what a lossy codec is for).
ImageU8 pattern(int channels, bool smooth = false) {
  ImageU8 img(37, 23, channels);
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      for (int c = 0; c < channels; ++c) {
        const std::size_t i = (static_cast<std::size_t>(y) * img.width() + x) * channels + c;
        img.at(x, y, c) = static_cast<std::uint8_t>(smooth ? 10 + 3 * x + 2 * y + 20 * c : i * 37 % 251);
      }
  return img;
}

TEST(ImageCodecs, EachFormatRoundTripsAndReadsWhatOpenCvWrites) {
  const std::string dir = test::scratch_dir("ImageCodecs.RoundTrip");
  for (int channels : {1, 3, 4}) {
    for (const char* ext : {".png", ".bmp", ".jpg"}) {
      const ImageU8 img = pattern(channels, std::strcmp(ext, ".jpg") == 0);
      const std::string path = dir + "/img" + std::to_string(channels) + ext;
      ASSERT_TRUE(write_image(path, img).ok()) << path;
      Result<ImageU8> back = read_image(path);
      ASSERT_TRUE(back.ok()) << path << ": " << back.status().to_string();
      ASSERT_EQ(back->width(), img.width());
      double error = 0;
      for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x)
          for (int c = 0; c < 4; ++c) {
            const int want = c == 3 ? (channels == 4 && std::strcmp(ext, ".jpg") != 0 ? img.at(x, y, 3) : 255)
                                    : img.at(x, y, channels == 1 ? 0 : c);
            error = std::max(error, std::abs(double(back->at(x, y, c)) - want));
          }
      if (std::strcmp(ext, ".jpg") == 0)
        EXPECT_LE(error, 6) << path;  // lossy, at quality 95
      else
        EXPECT_EQ(error, 0) << path;  // lossless
      // OpenCV reads ours as we do.
      expect_same_pixels(*back, decode_with_opencv(test::read_file(path)), path);
    }
  }
  // TIFF (LZW and uncompressed) and WebP (lossless), written by OpenCV.
  const ImageU8 rgba = pattern(4);
  cv::Mat bgra(rgba.height(), rgba.width(), CV_8UC4);
  cv::cvtColor(cv::Mat(rgba.height(), rgba.width(), CV_8UC4, const_cast<std::uint8_t*>(rgba.data())), bgra,
               cv::COLOR_RGBA2BGRA);
  for (const auto& [ext, params] :
       std::vector<std::pair<std::string, std::vector<int>>>{{".tiff", {cv::IMWRITE_TIFF_COMPRESSION, 5}},
                                                             {".tiff", {cv::IMWRITE_TIFF_COMPRESSION, 1}},
                                                             {".webp", {cv::IMWRITE_WEBP_QUALITY, 101}}}) {
    std::vector<std::uint8_t> bytes;
    ASSERT_TRUE(cv::imencode(ext, bgra, bytes, params));
    const std::string encoded(bytes.begin(), bytes.end());
    Result<ImageU8> back = decode(encoded, dir, "opencv" + ext);
    ASSERT_TRUE(back.ok()) << ext << ": " << back.status().to_string();
    // The same pixels OpenCV reads back (its WebP encoder changes the colour
    // of fully transparent pixels, so not always the pattern's).
    expect_same_pixels(*back, decode_with_opencv(encoded), ext);
    if (ext == ".tiff") expect_same_pixels(*back, rgba, ext);
  }
}

TEST(ImageCodecs, DamagedAndForeignDataIsNamed) {
  const std::string dir = test::scratch_dir("ImageCodecs.Errors");
  ASSERT_TRUE(write_image(dir + "/ok.png", pattern(3)).ok());
  ASSERT_TRUE(write_image(dir + "/ok.jpg", pattern(3)).ok());
  ASSERT_TRUE(write_image(dir + "/ok.bmp", pattern(3)).ok());
  const std::string png = test::read_file(dir + "/ok.png"), jpeg = test::read_file(dir + "/ok.jpg");
  auto message = [&](const std::string& bytes) {
    Result<ImageU8> r = decode(bytes, dir, "bad");
    EXPECT_FALSE(r.ok());
    return r.ok() ? std::string() : r.status().to_string();
  };
  EXPECT_NE(message(png.substr(0, png.size() / 2)).find("PNG:"), std::string::npos);
  EXPECT_NE(message(jpeg.substr(0, 200)).find("JPEG:"), std::string::npos);
  EXPECT_NE(message(std::string("\xABKTX 20\xBB\r\n\x1a\n", 12) + std::string(64, '\0')).find("KTX2"),
            std::string::npos);
  EXPECT_NE(message(std::string("RIFF\x10\0\0\0WEBPVP8 garbage", 23)).find("WebP:"), std::string::npos);
  EXPECT_NE(message("BM" + std::string(60, '\0')).find("BMP:"), std::string::npos);
  EXPECT_NE(message("plain text").find("not an image libg2p reads"), std::string::npos);
  // A BMP claiming 100000 x 100000 pixels is refused before any memory is taken.
  std::string huge = test::read_file(dir + "/ok.bmp");
  const std::uint32_t side = 100000;
  std::memcpy(&huge[18], &side, 4);
  std::memcpy(&huge[22], &side, 4);
  EXPECT_NE(message(huge).find("100000 x 100000"), std::string::npos);
  // Writing names the formats it knows.
  const Status tiff = write_image(dir + "/x.tiff", pattern(3));
  EXPECT_EQ(tiff.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(tiff.message().find("png, jpg, bmp"), std::string::npos);
}

}  // namespace
}  // namespace g2p
