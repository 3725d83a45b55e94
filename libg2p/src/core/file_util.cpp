#include "core/file_util.h"
#include "g2p/io.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace g2p::detail {

namespace fs = std::filesystem;

Status write_file_atomically(const std::string& path, const std::string& bytes) {
  const fs::path target(path);
  const fs::path tmp = target.parent_path() / (".tmp." + target.filename().string());
  {
    // C stdio, so that the operating system's reason (errno) reaches the
    // message: "No space left on device", "Permission denied", ...
    std::FILE* out = std::fopen(tmp.c_str(), "wb");
    if (out == nullptr) return Status::IoError(path + ": cannot open for writing: " + std::strerror(errno));
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), out) == bytes.size() && std::fflush(out) == 0;
    const int error = errno;
    const bool closed = std::fclose(out) == 0;
    if (!written || !closed) {
      const std::string why = std::strerror(written ? errno : error);
      std::error_code ec;
      fs::remove(tmp, ec);
      return Status::IoError(path + ": write failed: " + why);
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    const std::string why = ec.message();  // before remove() resets ec
    fs::remove(tmp, ec);
    return Status::IoError(path + ": cannot replace the file: " + why +
                           (fs::is_directory(target, ec) ? " (a folder of that name is in the way)" : ""));
  }
  return Status::Ok();
}

std::string npy_float32(const ImageF& image) {
  std::string shape = "(" + std::to_string(image.height()) + ", " + std::to_string(image.width()) +
                      (image.channels() > 1 ? ", " + std::to_string(image.channels()) + ")" : ")");
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': " + shape + ", }";
  while ((10 + header.size() + 1) % 64 != 0) header.push_back(' ');  // data aligned to 64 bytes
  header.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  out.push_back(static_cast<char>(header.size() & 0xFF));
  out.push_back(static_cast<char>(header.size() >> 8));
  out += header;
  out.append(reinterpret_cast<const char*>(image.data()), image.size() * sizeof(float));
  return out;
}

Status ensure_directory(const std::string& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return Status::Ok();
  if (fs::exists(dir, ec)) return Status::InvalidArgument(dir + ": exists and is not a folder");
  fs::create_directories(dir, ec);
  if (ec) return Status::IoError(dir + ": cannot create the folder: " + ec.message());
  return Status::Ok();
}

}  // namespace g2p::detail

namespace g2p {

Status write_text_file(const std::string& path, const std::string& text) {
  return detail::write_file_atomically(path, text);
}

}  // namespace g2p
