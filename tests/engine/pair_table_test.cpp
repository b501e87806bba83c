// The step's per-pair table (engine/pair_table.h) against std::map on the same operations:
// keys that collide in their home slot, values replaced and dropped, and growth past many
// doublings with every value still found.
#include "engine/pair_table.h"

#include <gtest/gtest.h>

#include <map>
#include <random>

namespace rbx {
namespace {

TEST(PairTable, FindsWhatWasPutAndForgetsWhatWasDropped) {
  PairTable<int> table;
  EXPECT_EQ(table.find(7), nullptr);
  table.put(7, 70);
  table.put(0, 1);
  ASSERT_NE(table.find(7), nullptr);
  EXPECT_EQ(*table.find(7), 70);
  EXPECT_EQ(*table.find(0), 1);
  table.put(7, 71);  // replaced
  EXPECT_EQ(*table.find(7), 71);
  table.drop(7);
  EXPECT_EQ(table.find(7), nullptr);
  EXPECT_EQ(*table.find(0), 1);
  table.put(7, 72);  // kept again in its old slot
  EXPECT_EQ(*table.find(7), 72);
  *table.find(0) = 2;  // a found value is the kept one
  EXPECT_EQ(*table.find(0), 2);
}

TEST(PairTable, AgreesWithAnOrderedMapOverManyRandomOperations) {
  // Keys as the step makes them (i * bodies + j) for a crowd of 1,000, so that many share a home
  // slot and the table doubles from 64 slots to tens of thousands.
  std::mt19937_64 random(2026);
  std::uniform_int_distribution<int> body(0, 999), what(0, 9);
  PairTable<long long> table;
  std::map<long long, long long> truth;
  for (int k = 0; k < 200000; ++k) {
    const int i = body(random), j = body(random);
    const long long key = static_cast<long long>(std::min(i, j)) * 1000 + std::max(i, j);
    const int op = what(random);
    if (op < 5) {
      table.put(key, k);
      truth[key] = k;
    } else if (op < 7) {
      table.drop(key);
      truth.erase(key);
    } else {
      const long long* found = table.find(key);
      const auto it = truth.find(key);
      ASSERT_EQ(found != nullptr, it != truth.end()) << key;
      if (found) {
        ASSERT_EQ(*found, it->second) << key;
      }
    }
  }
  for (const auto& [key, value] : truth) {
    ASSERT_NE(table.find(key), nullptr) << key;
    EXPECT_EQ(*table.find(key), value);
  }
}

}  // namespace
}  // namespace rbx
