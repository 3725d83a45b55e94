// Where the shipped model files are found (core/model_files.h).
#include "core/model_files.h"

#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#if defined(G2P_LIB_TO_MODEL_DIR) && defined(__unix__)
#include <dlfcn.h>
#endif

namespace g2p::detail {

namespace {

// share/g2p/models beside the shared object this function was loaded from;
// "" where that cannot be told (static builds find the executable instead,
// whose neighbourhood is checked the same way and simply holds nothing).
std::string library_relative_model_dir() {
#if defined(G2P_LIB_TO_MODEL_DIR) && defined(__unix__)
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&library_relative_model_dir), &info) != 0 && info.dli_fname != nullptr &&
      *info.dli_fname != '\0') {
    // A relative name (LD_LIBRARY_PATH=relative/dir) is relative to the folder the program started in.
    std::error_code ec;
    const std::filesystem::path library = std::filesystem::absolute(info.dli_fname, ec);
    if (!ec) return (library.parent_path() / G2P_LIB_TO_MODEL_DIR).lexically_normal().string();
  }
#endif
  return {};
}

}  // namespace

std::string shipped_model_file(const std::string& name) {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("G2P_MODEL_DIR"); env != nullptr && *env != '\0') dirs.emplace_back(env);
  if (std::string beside = library_relative_model_dir(); !beside.empty()) dirs.push_back(std::move(beside));
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
