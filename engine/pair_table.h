// A value per pair of bodies, looked up by the pair's key (i * bodies + j) in one flat array:
// open addressing with linear probing. The step asks it for every pair that passes the bounding
// check, twice a step; a node-based map spent most of that in cache misses on crowds of a
// thousand bodies, where a lookup here touches one slot, or a few neighbouring ones.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace rbx {

template <typename T>
class PairTable {
 public:
  /// The value kept for `key` (>= 0), or nullptr.
  T* find(long long key) {
    if (slots_.empty()) return nullptr;
    for (std::size_t s = home(key);; s = (s + 1) & mask()) {
      if (slots_[s].key == key) return slots_[s].kept ? &slots_[s].value : nullptr;
      if (slots_[s].key == kEmpty) return nullptr;
    }
  }
  /// Keeps `value` for `key` (>= 0), replacing any.
  void put(long long key, T value) {
    // Half full at most, so that a probe meets an empty slot within a few steps.
    if (2 * (used_ + 1) > slots_.size()) grow();
    Slot& s = slot(key);
    if (s.key == kEmpty) ++used_;
    s = {key, std::move(value), true};
  }
  /// Forgets `key`'s value. Its slot stays taken (a pair once seen keeps its place; the table
  /// never shrinks, as the set of pairs a run meets is bounded by its crowd's neighbourhoods).
  void drop(long long key) {
    if (find(key)) slot(key).kept = false;
  }

 private:
  static constexpr long long kEmpty = -1;
  struct Slot {
    long long key = kEmpty;
    T value{};
    bool kept = false;
  };
  std::size_t mask() const { return slots_.size() - 1; }
  std::size_t home(long long key) const {
    // Fibonacci hashing: keys of neighbouring pairs differ in their low bits.
    const std::uint64_t h = static_cast<std::uint64_t>(key) * 0x9E3779B97F4A7C15ull;
    return static_cast<std::size_t>(h >> 32) & mask();
  }
  Slot& slot(long long key) {
    std::size_t s = home(key);
    while (slots_[s].key != key && slots_[s].key != kEmpty) s = (s + 1) & mask();
    return slots_[s];
  }
  void grow() {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(old.empty() ? 64 : 2 * old.size(), Slot{});
    for (Slot& s : old)
      if (s.key != kEmpty) slot(s.key) = std::move(s);
  }
  std::vector<Slot> slots_;  // a power of two in size
  std::size_t used_ = 0;     // slots taken
};

}  // namespace rbx
