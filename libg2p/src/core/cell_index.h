// Private: the cells of a hash grid, keyed by packed integer coordinates,
// each holding one int (the head of a list of points threaded through an
// array of the caller's). Open addressing with linear probing in one array:
// no allocation per cell, where a std::unordered_map of a million cells
// spends most of a weld's time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace g2p::detail {

class CellIndex {
 public:
  // Room for `cells` keys before the table first grows (it is kept at most
  // half full, doubling when it would not be).
  explicit CellIndex(std::size_t cells = 0) {
    std::size_t capacity = 16;
    while (capacity < 2 * cells) capacity *= 2;
    slots_.assign(capacity, Slot{});
  }

  // The value of cell `key`, or nullptr when the cell holds none.
  const int* find(std::uint64_t key) const {
    for (std::size_t i = start(key);; i = (i + 1) & (slots_.size() - 1)) {
      const Slot& s = slots_[i];
      if (!s.used) return nullptr;
      if (s.key == key) return &s.value;
    }
  }
  // The value of cell `key`, made `value` if the cell is new. The reference
  // holds until the next call.
  int& at(std::uint64_t key, int value) {
    if (2 * (size_ + 1) > slots_.size()) grow();
    for (std::size_t i = start(key);; i = (i + 1) & (slots_.size() - 1)) {
      Slot& s = slots_[i];
      if (!s.used) {
        s = {key, value, true};
        ++size_;
        return s.value;
      }
      if (s.key == key) return s.value;
    }
  }
  std::size_t size() const { return size_; }

  // Packs cell coordinates, 21 bits each (wrapping: far cells may share a
  // key, which only costs a distance test).
  static std::uint64_t key(long long x, long long y, long long z) {
    return (static_cast<std::uint64_t>(x) & 0x1FFFFF) | ((static_cast<std::uint64_t>(y) & 0x1FFFFF) << 21) |
           ((static_cast<std::uint64_t>(z) & 0x1FFFFF) << 42);
  }

 private:
  struct Slot {
    std::uint64_t key = 0;
    int value = -1;
    bool used = false;
  };
  std::size_t start(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 20) & (slots_.size() - 1);
  }
  void grow() {
    std::vector<Slot> old(2 * slots_.size());
    old.swap(slots_);
    for (const Slot& s : old)
      if (s.used)
        for (std::size_t i = start(s.key);; i = (i + 1) & (slots_.size() - 1))
          if (!slots_[i].used) {
            slots_[i] = s;
            break;
          }
  }
  std::vector<Slot> slots_;
  std::size_t size_ = 0;
};

}  // namespace g2p::detail
