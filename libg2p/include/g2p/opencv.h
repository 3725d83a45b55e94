// Optional bridge between g2p::Image and cv::Mat, header-only. libg2p itself
// never includes it; callers that use OpenCV do. Channel order is kept as is
// (libg2p images are RGB(A); cv::cvtColor converts to OpenCV's BGR if needed).
#pragma once

#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>

#include "g2p/image.h"

namespace g2p {

template <typename T>
constexpr int cv_depth() {
  if constexpr (std::is_same_v<T, std::uint8_t>)
    return CV_8U;
  else if constexpr (std::is_same_v<T, float>)
    return CV_32F;
  else if constexpr (std::is_same_v<T, std::int32_t>)
    return CV_32S;
  else if constexpr (std::is_same_v<T, double>)
    return CV_64F;
  else if constexpr (std::is_same_v<T, std::uint16_t>)
    return CV_16U;
  else
    static_assert(sizeof(T) == 0, "no cv::Mat depth for this pixel type");
}

// A cv::Mat that views the image's pixels (no copy; valid while `image` lives).
template <typename T>
cv::Mat as_mat(Image<T>& image) {
  return cv::Mat(image.height(), image.width(), CV_MAKETYPE(cv_depth<T>(), image.channels()), image.data());
}

// A deep copy of the image as a cv::Mat.
template <typename T>
cv::Mat to_mat(const Image<T>& image) {
  return cv::Mat(image.height(), image.width(), CV_MAKETYPE(cv_depth<T>(), image.channels()),
                 const_cast<T*>(image.data()))
      .clone();
}

// A deep copy of a cv::Mat whose depth matches T; empty image if it does not.
template <typename T>
Image<T> from_mat(const cv::Mat& mat) {
  if (mat.empty() || mat.depth() != cv_depth<T>()) return {};
  Image<T> out(mat.cols, mat.rows, mat.channels());
  for (int y = 0; y < mat.rows; ++y) std::memcpy(out.pixel(0, y), mat.ptr<T>(y), out.row_stride() * sizeof(T));
  return out;
}

}  // namespace g2p
