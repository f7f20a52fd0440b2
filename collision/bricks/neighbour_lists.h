#pragma once
/// Per-brick neighbour lists stored flat: a brick's list lives inline in a 32-byte record (up to
/// kInline ids), and only a longer one (a base plate under dozens of bricks) spills to a vector
/// of its own, kept for reuse once the list shrinks again.
///
/// Why: the connectivity search reads the list of every brick it visits. As a vector of vectors
/// each read was two dependent cache misses (the vector, then its heap block) in a random order;
/// here it is one for all but the spilled lists.
/// Order: a list keeps the order its ids were appended in, and erase keeps the others' order
/// (the searches walk lists in order, and a part's brick numbering follows its search).
/// Thread safety: const functions may run concurrently; the rest need exclusive access.
#include <cstdint>
#include <span>
#include <vector>

namespace bw {

class NeighbourLists {
 public:
  static constexpr uint32_t kInline = 7;

  /// Ids with a list (all empty until appended to).
  uint32_t size() const { return uint32_t(records_.size()); }
  /// Grows to n lists; never shrinks.
  void grow(uint32_t n) {
    if (n > records_.size()) records_.resize(n);
  }
  std::span<const uint32_t> operator[](uint32_t id) const {
    const Record& r = records_[id];
    if (r.count <= kInline) return {r.ids, r.count};
    return spill_[r.ids[0]];
  }
  /// The list of `id`, writable in place (renumbering).
  std::span<uint32_t> mutableList(uint32_t id) {
    Record& r = records_[id];
    if (r.count <= kInline) return {r.ids, r.count};
    return spill_[r.ids[0]];
  }
  void append(uint32_t id, uint32_t v);
  /// Removes the first v from id's list (v must be listed), keeping the others' order.
  void erase(uint32_t id, uint32_t v);
  void clear(uint32_t id);
  /// Moves list fromId of `from` to list toId of this (empty before), leaving from's empty.
  void takeFrom(NeighbourLists& from, uint32_t fromId, uint32_t toId);
  /// Asks the cache for id's record ahead of reading it.
  void prefetch(uint32_t id) const { __builtin_prefetch(&records_[id]); }

 private:
  struct Record {
    uint32_t count = 0;        // 4   ids listed; above kInline they live in spill_[ids[0]]
    uint32_t ids[kInline]{};   // 32
  };
  static_assert(sizeof(Record) == 32);
  uint32_t newSpill();
  void releaseSpill(uint32_t s);

  std::vector<Record> records_;              // by brick id
  std::vector<std::vector<uint32_t>> spill_;  // lists longer than kInline
  std::vector<uint32_t> freeSpill_;           // spill_ entries not in use (their capacity kept)
};

}  // namespace bw
