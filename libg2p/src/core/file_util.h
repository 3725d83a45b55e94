// Private: writing files so that a failure never leaves half a file behind.
#pragma once

#include <string>

#include "g2p/image.h"
#include "g2p/status.h"

namespace g2p::detail {

// Writes `bytes` to a temporary file beside `path` and renames it over `path`.
Status write_file_atomically(const std::string& path, const std::string& bytes);

// A float32 image as a NumPy .npy file (format 1.0): shape (height, width)
// for one channel, (height, width, channels) otherwise.
std::string npy_float32(const ImageF& image);

// Creates `dir` and its parents if needed; an error if it is not a folder.
Status ensure_directory(const std::string& dir);

}  // namespace g2p::detail
