#include "support/test_data.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace g2p::test {

std::string asset_path(const std::string& name) {
  return std::string(G2P_TEST_SHARED_ASSETS) + "/" + name + "/" + name + ".glb";
}
std::string labels_json_path() { return std::string(G2P_TEST_SHARED_ASSETS) + "/labels.json"; }
std::string assimp_model(const std::string& relative) { return std::string(G2P_TEST_ASSIMP_MODELS) + "/" + relative; }
std::string source_path(const std::string& relative) { return std::string(G2P_TEST_SOURCE_DIR) + "/" + relative; }
std::string generated_path(const std::string& file) { return std::string(G2P_TEST_SHARED_GENERATED) + "/" + file; }
std::string shared_model_path(const std::string& relative) {
  return std::string(G2P_TEST_SHARED_MODELS) + "/" + relative;
}

std::string scratch_dir(const std::string& test_name) {
  // ctest runs tests in parallel, and several tests may ask for the same name
  // (a shared fixture): the running test's own name keeps their folders apart.
  std::filesystem::path dir = std::filesystem::path(G2P_TEST_BINARY_DIR) / "scratch";
  if (const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info()) {
    std::string running = std::string(info->test_suite_name()) + "." + info->name();
    for (char& c : running)
      if (c == '/') c = '_';
    dir /= running;
  }
  dir /= test_name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string gltf_json_text(const std::string& path) {
  const std::string bytes = read_file(path);
  if (bytes.compare(0, 4, "glTF") != 0 || bytes.size() < 20) return bytes;
  std::uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 12, 4);  // GLB: little-endian, as every platform libg2p builds on
  return bytes.substr(20, length);
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
  ASSERT_TRUE(out.good()) << "cannot write " << path;
}

}  // namespace g2p::test
