// The hash grid's cell table: every key keeps its value as the table grows,
// and absent keys are absent.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <unordered_map>

#include "core/cell_index.h"

namespace g2p {
namespace {

TEST(CellIndex, KeepsEveryCellAsItGrowsAndFindsNoOther) {
  detail::CellIndex cells;  // no room given: it grows from 16 slots
  std::unordered_map<std::uint64_t, int> truth;
  std::mt19937 random(3);
  std::uniform_int_distribution<int> coordinate(-300, 300);
  for (int i = 0; i < 200000; ++i) {
    const std::uint64_t key = detail::CellIndex::key(coordinate(random), coordinate(random), coordinate(random) / 10);
    const auto [it, added] = truth.emplace(key, i);
    const int got = cells.at(key, i);
    EXPECT_EQ(got, it->second);  // a new cell takes the value, an old one keeps its own
    if (added) {
      // Changing a value through the reference sticks.
      cells.at(key, -7) = i;
    }
  }
  EXPECT_EQ(cells.size(), truth.size());
  for (const auto& [key, value] : truth) {
    const int* found = cells.find(key);
    ASSERT_NE(found, nullptr);
    EXPECT_EQ(*found, value);
  }
  EXPECT_EQ(cells.find(detail::CellIndex::key(1000, 1000, 1000)), nullptr);
  // Neighbouring and negative coordinates are different cells.
  EXPECT_NE(detail::CellIndex::key(-1, 0, 0), detail::CellIndex::key(0, 0, 0));
  EXPECT_NE(detail::CellIndex::key(0, -1, 0), detail::CellIndex::key(0, 0, -1));
}

}  // namespace
}  // namespace g2p
