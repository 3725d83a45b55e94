// Image<T>: a dense, row-major, interleaved-channel image. The currency of the
// render and segment stages (RGB, face-ID, depth, label maps) and of decoded
// material textures. Conversion to and from cv::Mat lives in g2p/opencv.h,
// which only callers that use OpenCV include.
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace g2p {

namespace detail {

// The storage of an Image: memory that comes zeroed from calloc, and elements
// that a plain resize leaves as they are. A fresh image filled with zero then
// costs nothing until a pixel is written: large blocks come straight from the
// kernel, whose untouched pages read as zero and are never faulted in. On the
// shared virtual machines this library runs on, faulting in a page costs more
// than rendering it (docs/performance.md, "Fresh memory"), and a view's
// material buffers or a label map's probabilities are mostly background.
template <typename T>
struct ZeroedAllocator {
  static_assert(std::is_trivially_default_constructible_v<T> && std::is_trivially_destructible_v<T>,
                "images hold plain values");
  using value_type = T;
  ZeroedAllocator() = default;
  template <typename U>
  ZeroedAllocator(const ZeroedAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    void* p = std::calloc(n == 0 ? 1 : n, sizeof(T));
    if (p == nullptr) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) noexcept { std::free(p); }
  // Default-initialises: leaves calloc's zeros (or whatever was there) alone.
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <typename U>
  bool operator==(const ZeroedAllocator<U>&) const noexcept {
    return true;
  }
  template <typename U>
  bool operator!=(const ZeroedAllocator<U>&) const noexcept {
    return false;
  }
};

}  // namespace detail

template <typename T>
class Image {
 public:
  using value_type = T;
  using Storage = std::vector<T, detail::ZeroedAllocator<T>>;

  Image() = default;
  Image(int width, int height, int channels, T fill = T{}) { reset(width, height, channels, fill); }

  // Gives the image a new shape, every value `fill`, reusing the storage it
  // already has when large enough (no fresh memory for repeated renders).
  // Fresh storage filled with zero is left as calloc gave it: its pages are
  // faulted in only where a value is written.
  void reset(int width, int height, int channels, T fill = T{}) {
    assert(width >= 0 && height >= 0 && channels >= 1);
    width_ = width, height_ = height, channels_ = channels;
    const std::size_t n = static_cast<std::size_t>(width) * height * channels;
    if (n > data_.capacity() && is_zero(fill)) {
      Storage fresh;
      fresh.resize(n);  // default-initialised: calloc's zeros
      data_.swap(fresh);
    } else {
      data_.assign(n, fill);
    }
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
  Storage& storage() { return data_; }
  const Storage& storage() const { return data_; }

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

  // All bits zero (so +0.0 but not -0.0): what calloc gives.
  static bool is_zero(const T& v) {
    const T zero{};
    return std::memcmp(&v, &zero, sizeof(T)) == 0;
  }

  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
  Storage data_;
};

using ImageU8 = Image<std::uint8_t>;   // colour, 0..255 per channel
using ImageF = Image<float>;           // depth, normals, linear factors
using ImageI32 = Image<std::int32_t>;  // face IDs, labels (-1 = none)

}  // namespace g2p
