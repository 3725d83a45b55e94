// Private: the exact squared Euclidean distance transform of a 3D grid
// (Felzenszwalb and Huttenlocher 2012, "Distance transforms of sampled
// functions"), separable along the axes, lines side by side. The one copy
// that the partition completer (with labels: the nearest seed's) and the
// voxel grid (the distance to the nearest occupied cell) share.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <vector>

namespace g2p::detail {

// One line: d[q] = min_p (q - p)^2 + f[p] over the finite samples (in double
// whatever T is), and the minimising sample's label. v and z: n and n + 1
// scratch values.
template <typename T>
void squared_distance_line(const T* f, const int* label, int n, T* d, int* label_out, int* v, double* z) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!(f[q] < std::numeric_limits<T>::infinity())) continue;
    const double fq = static_cast<double>(f[q]) + static_cast<double>(q) * q;
    double s = -kInfinity;
    while (k >= 0) {
      const int p = v[k];
      s = (fq - (static_cast<double>(f[p]) + static_cast<double>(p) * p)) / (2.0 * (q - p));
      if (s <= z[k]) {
        --k;
        s = -kInfinity;
      } else {
        break;
      }
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kInfinity;
  }
  if (k < 0) {
    std::fill(d, d + n, std::numeric_limits<T>::infinity());
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const int p = v[j];
    d[q] = static_cast<T>(static_cast<double>(q - p) * (q - p) + static_cast<double>(f[p]));
    if (label_out != nullptr) label_out[q] = label[p];
  }
}

// In place on a grid of dims[0] x dims[1] x dims[2] cells, x fastest: f
// (squared distance in cells^2 at the seeds, +infinity elsewhere) becomes the
// squared distance to the nearest seed plus its value; `label`, if given,
// the nearest seed's label.
template <typename T>
void squared_distance_transform(const std::array<int, 3>& dims, std::vector<T>& f, std::vector<int>* label) {
  const std::size_t strides[3] = {1, static_cast<std::size_t>(dims[0]),
                                  static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1])};
  for (int axis = 0; axis < 3; ++axis) {
    const int n = dims[static_cast<std::size_t>(axis)];
    const int a1 = axis == 0 ? 1 : 0, a2 = axis == 2 ? 1 : 2;
    const int lines = dims[static_cast<std::size_t>(a1)] * dims[static_cast<std::size_t>(a2)];
    tbb::parallel_for(tbb::blocked_range<int>(0, lines, 64), [&](const tbb::blocked_range<int>& r) {
      std::vector<T> in(static_cast<std::size_t>(n)), out(static_cast<std::size_t>(n));
      std::vector<int> lin(static_cast<std::size_t>(n)), lout(static_cast<std::size_t>(n)),
          v(static_cast<std::size_t>(n));
      std::vector<double> z(static_cast<std::size_t>(n) + 1);
      for (int line = r.begin(); line != r.end(); ++line) {
        const std::size_t base = static_cast<std::size_t>(line % dims[static_cast<std::size_t>(a1)]) * strides[a1] +
                                 static_cast<std::size_t>(line / dims[static_cast<std::size_t>(a1)]) * strides[a2];
        const std::size_t s = strides[axis];
        for (int q = 0; q < n; ++q) in[static_cast<std::size_t>(q)] = f[base + static_cast<std::size_t>(q) * s];
        if (label != nullptr)
          for (int q = 0; q < n; ++q)
            lin[static_cast<std::size_t>(q)] = (*label)[base + static_cast<std::size_t>(q) * s];
        squared_distance_line(in.data(), lin.data(), n, out.data(), label != nullptr ? lout.data() : nullptr, v.data(),
                              z.data());
        for (int q = 0; q < n; ++q) f[base + static_cast<std::size_t>(q) * s] = out[static_cast<std::size_t>(q)];
        if (label != nullptr)
          for (int q = 0; q < n; ++q)
            (*label)[base + static_cast<std::size_t>(q) * s] = lout[static_cast<std::size_t>(q)];
      }
    });
  }
}

}  // namespace g2p::detail
