// Where the shipped model files are found (core/model_files.h).
#include "core/model_files.h"

#include <cstdlib>
#include <filesystem>
#include <vector>

namespace g2p::detail {

std::string shipped_model_file(const std::string& name) {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("G2P_MODEL_DIR"); env != nullptr && *env != '\0') dirs.emplace_back(env);
#ifdef G2P_SOURCE_MODEL_DIR
  dirs.emplace_back(G2P_SOURCE_MODEL_DIR);
#endif
#ifdef G2P_INSTALL_MODEL_DIR
  dirs.emplace_back(G2P_INSTALL_MODEL_DIR);
#endif
  for (const std::string& d : dirs) {
    std::error_code ec;
    const std::filesystem::path file = std::filesystem::path(d) / name;
    if (std::filesystem::is_regular_file(file, ec)) return file.string();
  }
  return {};
}

}  // namespace g2p::detail
