#include <gtest/gtest.h>

#include <filesystem>

#include "g2p/io.h"
#include "support/test_data.h"

namespace g2p {
namespace {

TEST(ImageIo, PngRoundTripIsLossless) {
  const std::string dir = test::scratch_dir("ImageIo.RoundTrip");
  for (int channels : {1, 3, 4}) {
    ImageU8 img(17, 9, channels);
    for (std::size_t i = 0; i < img.size(); ++i) img.data()[i] = static_cast<std::uint8_t>(i * 37 % 251);
    const std::string path = dir + "/img" + std::to_string(channels) + ".png";
    ASSERT_TRUE(write_image(path, img).ok());
    Result<ImageU8> back = read_image(path);  // always RGBA
    ASSERT_TRUE(back.ok()) << back.status().to_string();
    ASSERT_EQ(back->width(), 17);
    ASSERT_EQ(back->height(), 9);
    ASSERT_EQ(back->channels(), 4);
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 17; ++x)
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(back->at(x, y, c), img.at(x, y, channels == 1 ? 0 : c)) << x << "," << y << "," << c;
  }
}

TEST(ImageIo, ErrorsAndNoHalfWrittenFiles) {
  const std::string dir = test::scratch_dir("ImageIo.Errors");
  EXPECT_EQ(read_image(dir + "/none.png").status().code(), StatusCode::kNotFound);
  test::write_file(dir + "/bad.png", "not a png");
  EXPECT_EQ(read_image(dir + "/bad.png").status().code(), StatusCode::kParseError);
  EXPECT_EQ(write_image(dir + "/x.png", ImageU8()).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(write_image(dir + "/x.png", ImageU8(2, 2, 2)).code(), StatusCode::kInvalidArgument);
  const Status unknown = write_image(dir + "/x.unknownext", ImageU8(2, 2, 3));
  EXPECT_EQ(unknown.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(unknown.message().find("'.unknownext'"), std::string::npos) << unknown.to_string();
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.unknownext"));
  EXPECT_EQ(write_image(dir + "/no/such/dir/x.png", ImageU8(2, 2, 3)).code(), StatusCode::kIoError);
  // Nothing but the input remains in the folder.
  int files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1);
}

TEST(ImageIo, AFullDiskIsNamedAsSuch) {
  // The temporary file a write goes through is made to point at /dev/full,
  // where every write fails with ENOSPC, as on a full disk.
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string dir = test::scratch_dir("ImageIo.DiskFull");
  std::filesystem::create_symlink("/dev/full", dir + "/.tmp.view.png");
  std::filesystem::create_symlink("/dev/full", dir + "/.tmp.run.json");
  const Status image = write_image(dir + "/view.png", ImageU8(64, 64, 3));
  EXPECT_EQ(image.code(), StatusCode::kIoError);
  EXPECT_NE(image.message().find("No space left on device"), std::string::npos) << image.to_string();
  const Status text = write_text_file(dir + "/run.json", std::string(100000, 'x'));
  EXPECT_EQ(text.code(), StatusCode::kIoError);
  EXPECT_NE(text.message().find("No space left on device"), std::string::npos) << text.to_string();
  EXPECT_FALSE(std::filesystem::exists(dir + "/view.png"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/run.json"));
}

// A folder where the file should go: the message says what is in the way (it
// once read "cannot replace the file: Success"), and nothing is left behind.
TEST(WriteTextFile, AFolderInTheWayIsNamed) {
  const std::string dir = test::scratch_dir("WriteTextFileFolder");
  std::filesystem::create_directories(dir + "/report.json");
  const Status s = write_text_file(dir + "/report.json", "{}\n");
  EXPECT_EQ(s.code(), StatusCode::kIoError);
  EXPECT_EQ(s.message().find("Success"), std::string::npos) << s.to_string();
  EXPECT_NE(s.message().find("a folder of that name is in the way"), std::string::npos) << s.to_string();
  EXPECT_FALSE(std::filesystem::exists(dir + "/.tmp.report.json"));
}

}  // namespace
}  // namespace g2p
