// Internal: items grouped by an integer key in compressed rows, by a counting sort.
//
// The mesh stages group things by vertex again and again (a vertex's sharp edges, an edge's
// sides by its smaller vertex): a comparison sort of every item costs n log n and runs on one
// core, while counting the keys, summing the counts and placing each item is linear and keeps
// the items of a key in the order they were given, so the result needs no tie-break to be
// deterministic.
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

namespace vertexflow {

/// The items of each key k in [0, num_keys): items[start[k] .. start[k + 1]), in the order
/// they were emitted. `Offset` may be a 32-bit index where the item count allows (4 bytes per
/// key fewer).
template <class Item, class Offset = std::size_t>
struct KeyBuckets {
  std::vector<Offset> start;
  std::vector<Item> items;

  [[nodiscard]] std::span<Item> of(std::size_t key) {
    const auto begin = static_cast<std::size_t>(start[key]), end = static_cast<std::size_t>(start[key + 1]);
    return {items.data() + begin, end - begin};
  }
};

/// Groups items by key: `for_each(emit)` calls emit(key, item) for every item, with key in
/// [0, num_keys), and must emit the same sequence each time, as it is called twice (once to
/// count, once to place). A stable counting sort: linear time, items of a key in emitted order.
template <class Item, class Offset = std::size_t, class ForEach>
KeyBuckets<Item, Offset> bucket_by_key(std::size_t num_keys, ForEach&& for_each) {
  KeyBuckets<Item, Offset> buckets;
  buckets.start.assign(num_keys + 1, 0);
  for_each([&](std::size_t key, const Item&) { ++buckets.start[key + 1]; });
  for (std::size_t k = 0; k < num_keys; ++k) buckets.start[k + 1] += buckets.start[k];
  buckets.items.resize(static_cast<std::size_t>(buckets.start[num_keys]));
  std::vector<Offset> fill(buckets.start.begin(), buckets.start.end() - 1);
  for_each([&](std::size_t key, const Item& item) { buckets.items[static_cast<std::size_t>(fill[key]++)] = item; });
  return buckets;
}

/// Items [first, last) of chunk `chunk` when n items are cut into num_chunks runs of
/// ceil(n / num_chunks) (the last runs shorter or empty): how the callers of the two functions
/// below cut their items.
inline std::pair<std::size_t, std::size_t> chunk_range(std::size_t n, std::size_t num_chunks, std::size_t chunk) {
  const std::size_t length = (n + num_chunks - 1) / num_chunks;
  return {std::min(n, chunk * length), std::min(n, (chunk + 1) * length)};
}

/// The counting sort of bucket_by_key_in_chunks below, for a caller that stores the items
/// itself: `for_each_in(chunk, emit)` calls emit(key, item) for the items of `chunk` (the same
/// sequence each time, as it is called twice per chunk); `reserve(total)` is called once the
/// items are counted, and then `place(position, item)` for every item, from several threads,
/// each position once. Returns the keys' starts: key k's items are placed at [start[k],
/// start[k + 1]), chunk after chunk and in emitted order within a chunk, whatever the threads.
/// The chunks are counted and placed in parallel, from per-chunk counts (num_chunks x num_keys
/// of them, so for a few chunks).
template <class Offset, class ForEachIn, class Reserve, class Place>
std::vector<Offset> place_by_key_in_chunks(std::size_t num_keys, std::size_t num_chunks, ForEachIn&& for_each_in,
                                           Reserve&& reserve, Place&& place) {
  std::vector<std::vector<Offset>> next(num_chunks);
  tbb::parallel_for(std::size_t{0}, num_chunks, [&](std::size_t c) {
    std::vector<Offset>& count = next[c];
    count.assign(num_keys, 0);
    for_each_in(c, [&](std::size_t key, const auto&) { ++count[key]; });
  });
  std::vector<Offset> start(num_keys + 1, 0);
  for (std::size_t k = 0; k < num_keys; ++k) {  // counts -> each chunk's first place for key k
    Offset at = start[k];
    for (std::vector<Offset>& count : next) {
      const Offset n = count[k];
      count[k] = at;
      at += n;
    }
    start[k + 1] = at;
  }
  reserve(static_cast<std::size_t>(start[num_keys]));
  tbb::parallel_for(std::size_t{0}, num_chunks, [&](std::size_t c) {
    std::vector<Offset>& at = next[c];
    for_each_in(c, [&](std::size_t key, const auto& item) { place(static_cast<std::size_t>(at[key]++), item); });
  });
  return start;
}

/// bucket_by_key over the items of `num_chunks` fixed chunks, counted and placed in parallel:
/// `for_each_in(chunk, emit)` calls emit(key, item) for the items of `chunk` (the same sequence
/// each time). The result is bucket_by_key's over the chunks' items in chunk order, whatever the
/// threads (place_by_key_in_chunks).
template <class Item, class Offset = std::size_t, class ForEachIn>
KeyBuckets<Item, Offset> bucket_by_key_in_chunks(std::size_t num_keys, std::size_t num_chunks,
                                                 ForEachIn&& for_each_in) {
  KeyBuckets<Item, Offset> buckets;
  buckets.start = place_by_key_in_chunks<Offset>(
      num_keys, num_chunks, for_each_in, [&](std::size_t total) { buckets.items.resize(total); },
      [&](std::size_t at, const Item& item) { buckets.items[at] = item; });
  return buckets;
}

}  // namespace vertexflow
