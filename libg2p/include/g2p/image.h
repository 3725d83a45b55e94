// Image<T>: a dense, row-major, interleaved-channel image. The currency of the
// render and segment stages (RGB, face-ID, depth, label maps) and of decoded
// material textures. Conversion to and from cv::Mat lives in g2p/opencv.h,
// which only callers that use OpenCV include.
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace g2p {

template <typename T>
class Image {
 public:
  using value_type = T;

  Image() = default;
  Image(int width, int height, int channels, T fill = T{})
      : width_(width),
        height_(height),
        channels_(channels),
        data_(static_cast<std::size_t>(width) * height * channels, fill) {
    assert(width >= 0 && height >= 0 && channels >= 1);
  }

  // Gives the image a new shape, every value `fill`, reusing the storage it
  // already has when large enough (no fresh memory for repeated renders).
  void reset(int width, int height, int channels, T fill = T{}) {
    assert(width >= 0 && height >= 0 && channels >= 1);
    width_ = width, height_ = height, channels_ = channels;
    data_.assign(static_cast<std::size_t>(width) * height * channels, fill);
  }
  // Empties the image (keeps the storage for a later reset).
  void clear() {
    width_ = height_ = channels_ = 0;
    data_.clear();
  }

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  bool empty() const { return data_.empty(); }
  std::size_t size() const { return data_.size(); }  // number of T values
  std::size_t row_stride() const { return static_cast<std::size_t>(width_) * channels_; }

  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  std::vector<T>& storage() { return data_; }
  const std::vector<T>& storage() const { return data_; }

  T* pixel(int x, int y) { return data_.data() + index(x, y, 0); }
  const T* pixel(int x, int y) const { return data_.data() + index(x, y, 0); }
  T& at(int x, int y, int c = 0) { return data_[index(x, y, c)]; }
  const T& at(int x, int y, int c = 0) const { return data_[index(x, y, c)]; }

  bool operator==(const Image& o) const {
    return width_ == o.width_ && height_ == o.height_ && channels_ == o.channels_ && data_ == o.data_;
  }
  bool operator!=(const Image& o) const { return !(*this == o); }

 private:
  std::size_t index(int x, int y, int c) const {
    assert(x >= 0 && x < width_ && y >= 0 && y < height_ && c >= 0 && c < channels_);
    return (static_cast<std::size_t>(y) * width_ + x) * channels_ + c;
  }

  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
  std::vector<T> data_;
};

using ImageU8 = Image<std::uint8_t>;   // colour, 0..255 per channel
using ImageF = Image<float>;           // depth, normals, linear factors
using ImageI32 = Image<std::int32_t>;  // face IDs, labels (-1 = none)

}  // namespace g2p
