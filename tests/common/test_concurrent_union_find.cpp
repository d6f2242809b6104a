// The concurrent union-find of src/common/concurrent_union_find.h: united on all threads, its
// sets and their numbers are those of a serial flood fill over the same pairs, on one thread or
// two, whatever order the pairs come in.
#include "common/concurrent_union_find.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

namespace vertexflow {
namespace {

// Sets numbered by a breadth-first flood fill from each unlabelled index in increasing order.
std::vector<Index> flood_fill_numbers(Index n, const std::vector<std::pair<Index, Index>>& pairs) {
  std::vector<std::vector<Index>> adjacent(static_cast<std::size_t>(n));
  for (const auto& [a, b] : pairs) {
    adjacent[static_cast<std::size_t>(a)].push_back(b);
    adjacent[static_cast<std::size_t>(b)].push_back(a);
  }
  std::vector<Index> number(static_cast<std::size_t>(n), -1);
  Index sets = 0;
  for (Index seed = 0; seed < n; ++seed) {
    if (number[static_cast<std::size_t>(seed)] >= 0) continue;
    std::vector<Index> queue{seed};
    number[static_cast<std::size_t>(seed)] = sets;
    for (std::size_t head = 0; head < queue.size(); ++head)
      for (const Index j : adjacent[static_cast<std::size_t>(queue[head])])
        if (number[static_cast<std::size_t>(j)] < 0) {
          number[static_cast<std::size_t>(j)] = sets;
          queue.push_back(j);
        }
    ++sets;
  }
  return number;
}

std::vector<Index> union_find_numbers(Index n, const std::vector<std::pair<Index, Index>>& pairs, Index& sets) {
  std::vector<Index> storage;
  ConcurrentUnionFind union_find(storage, n);
  parallel_for_index(
      static_cast<Index>(pairs.size()),
      [&](Index k) {
        union_find.unite(pairs[static_cast<std::size_t>(k)].first, pairs[static_cast<std::size_t>(k)].second);
      },
      64);
  sets = union_find.number_sets();
  return storage;
}

// n indices, `links` random pairs mostly between near indices (long chains that cross the
// threads' ranges) and some far apart, so that sets merge from both ends at once.
std::vector<std::pair<Index, Index>> random_pairs(Index n, Index links, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<Index> any(0, n - 1), near(1, 8);
  std::vector<std::pair<Index, Index>> pairs;
  for (Index k = 0; k < links; ++k) {
    const Index a = any(random);
    const Index b = k % 5 == 0 ? any(random) : std::min<Index>(n - 1, a + near(random));
    pairs.emplace_back(a, b);
  }
  return pairs;
}

TEST(ConcurrentUnionFind, NumbersTheSetsAsASerialFloodFill) {
  // From one big set to many small ones and isolated indices (fewer links than indices).
  for (const auto& [n, links] : {std::pair<Index, Index>{200000, 400000}, {200000, 60000}, {1000, 0}, {1, 0}}) {
    auto pairs = random_pairs(n, links, static_cast<unsigned>(n + links));
    const std::vector<Index> expected = flood_fill_numbers(n, pairs);
    const Index expected_sets = *std::max_element(expected.begin(), expected.end()) + 1;
    for (const int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      Index sets = 0;
      EXPECT_EQ(union_find_numbers(n, pairs, sets), expected)
          << n << " indices, " << links << " links, " << threads << " threads";
      EXPECT_EQ(sets, expected_sets);
    }
    // The pairs reversed and in another order: the same sets, the same numbers.
    std::shuffle(pairs.begin(), pairs.end(), std::mt19937(7));
    for (auto& [a, b] : pairs) std::swap(a, b);
    Index sets = 0;
    EXPECT_EQ(union_find_numbers(n, pairs, sets), expected) << n << " indices, " << links << " links, shuffled";
  }
}

}  // namespace
}  // namespace vertexflow
