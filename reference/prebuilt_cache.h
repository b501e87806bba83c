// Library objects built once from scene shapes and kept across queries, as a user holding them
// would: the "prebuilt" query variants, which time a library's query without the cost of
// building its shape (the report shows that cost apart).
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "engine/polyhedron.h"

namespace rbx {

/// A few built values keyed by one or two scene shapes. The key holds the shapes' shared_ptrs,
/// which keep them alive, so an address reused by a later shape can never hit a stale entry.
/// At most kEntries values (the oldest goes first); one cache per thread and per variant.
template <class Value>
class PrebuiltCache {
 public:
  using Shape = std::shared_ptr<const ConvexPolyhedron>;
  static constexpr size_t kEntries = 4;

  /// The value built for (a, b), built by `build()` on first use.
  template <class Build>
  Value& get(const Shape& a, const Shape& b, Build&& build) {
    for (Entry& e : entries_)
      if (e.a == a && e.b == b) return *e.value;
    if (entries_.size() >= kEntries) entries_.erase(entries_.begin());
    entries_.push_back({a, b, std::make_unique<Value>(build())});
    return *entries_.back().value;
  }

 private:
  struct Entry {
    Shape a, b;
    std::unique_ptr<Value> value;
  };
  std::vector<Entry> entries_;
};

}  // namespace rbx
