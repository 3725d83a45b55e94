// Private: disjoint sets over 0..n-1 with path halving, the one copy that the
// region grower, the mesh checks, the closed-part check and the alpha wrap's
// hole count share.
#pragma once

#include <cstddef>
#include <numeric>
#include <vector>

namespace g2p::detail {

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }

  // The root of x's set; halves the path on the way.
  int find(int x) {
    while (parent_[static_cast<std::size_t>(x)] != x) {
      parent_[static_cast<std::size_t>(x)] = parent_[static_cast<std::size_t>(parent_[static_cast<std::size_t>(x)])];
      x = parent_[static_cast<std::size_t>(x)];
    }
    return x;
  }

  // Joins a's set to b's: a's root points to b's (b's root found first).
  void unite(int a, int b) {
    const int root_b = find(b);
    parent_[static_cast<std::size_t>(find(a))] = root_b;
  }

 private:
  std::vector<int> parent_;
};

}  // namespace g2p::detail
