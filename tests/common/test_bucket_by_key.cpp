// The counting sorts of src/common/bucket_by_key.h: the chunked, parallel one groups exactly as
// the serial one does over the same items, whatever the chunks.
#include "common/bucket_by_key.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <utility>
#include <vector>

namespace vertexflow {
namespace {

// Items (key, payload) with keys skewed towards the low ones and some keys never used.
std::vector<std::pair<std::size_t, int>> random_items(std::size_t count, std::size_t num_keys, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<std::size_t> uniform(0, num_keys - 1);
  std::vector<std::pair<std::size_t, int>> items;
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t key = std::min(uniform(random), uniform(random)) / 2 * 2;  // odd keys stay empty
    items.emplace_back(key, static_cast<int>(k));
  }
  return items;
}

TEST(BucketByKey, GroupsStablyByKey) {
  const auto items = random_items(5000, 101, 1);
  const KeyBuckets<int> buckets = bucket_by_key<int>(101, [&](auto&& emit) {
    for (const auto& [key, payload] : items) emit(key, payload);
  });
  ASSERT_EQ(buckets.start.size(), 102u);
  EXPECT_EQ(buckets.items.size(), items.size());
  KeyBuckets<int> copy = buckets;
  for (std::size_t key = 0; key < 101; ++key) {
    std::vector<int> expected;
    for (const auto& [k, payload] : items)
      if (k == key) expected.push_back(payload);
    const auto got = copy.of(key);
    EXPECT_EQ(std::vector<int>(got.begin(), got.end()), expected) << "key " << key;
  }
}

TEST(BucketByKey, InChunksGivesTheSerialResult) {
  for (const std::size_t count : {0ul, 1ul, 7ul, 5000ul}) {
    const auto items = random_items(count, 101, 2 + static_cast<unsigned>(count));
    const KeyBuckets<int, std::uint32_t> serial = bucket_by_key<int, std::uint32_t>(101, [&](auto&& emit) {
      for (const auto& [key, payload] : items) emit(key, payload);
    });
    for (const std::size_t chunks : {1ul, 3ul, 8ul, 64ul}) {  // 64 > 7 items: empty chunks
      const KeyBuckets<int, std::uint32_t> chunked =
          bucket_by_key_in_chunks<int, std::uint32_t>(101, chunks, [&](std::size_t part, auto&& emit) {
            const auto [first, last] = chunk_range(count, chunks, part);
            for (std::size_t k = first; k < last; ++k) emit(items[k].first, items[k].second);
          });
      EXPECT_EQ(chunked.start, serial.start) << count << " items in " << chunks << " chunks";
      EXPECT_EQ(chunked.items, serial.items) << count << " items in " << chunks << " chunks";
    }
  }
}

// The chunks cover [0, n) in order, each item once, and none is longer than ceil(n / chunks).
TEST(BucketByKey, ChunkRangesTileTheItems) {
  for (const std::size_t n : {0ul, 1ul, 7ul, 8ul, 5000ul})
    for (const std::size_t chunks : {1ul, 2ul, 3ul, 8ul, 64ul}) {
      std::size_t next = 0;
      for (std::size_t c = 0; c < chunks; ++c) {
        const auto [first, last] = chunk_range(n, chunks, c);
        EXPECT_EQ(first, next) << n << " items, chunk " << c << " of " << chunks;
        EXPECT_LE(first, last);
        EXPECT_LE(last - first, (n + chunks - 1) / chunks);
        next = last;
      }
      EXPECT_EQ(next, n) << n << " items in " << chunks << " chunks";
    }
}

}  // namespace
}  // namespace vertexflow
