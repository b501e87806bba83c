// The report's distance and time-of-impact sections, rendered from sections made by hand: the
// rows in their ranked order, each kind of disagreement named in its row with its count and
// first sample, an early stop's measured separation, the command that reproduces the samples,
// and names that stay text in Markdown.
#include "comparisons/output/query_report.h"

#include <gtest/gtest.h>

#include <string>

namespace rbx {
namespace {

QueryFamily toi_family() {
  QueryFamily f;
  f.scene = "explore/toi";
  f.error = "time_err";
  f.count = 300;
  QueryFamilyRow good;
  good.backend = "custom";
  good.samples = 300;
  good.measured = 131;
  good.p50 = 3e-10;
  good.timed = 40;
  good.time_s = 9e-6;
  good.time_q25_s = 1.3e-6;
  good.time_q75_s = 1.6e-5;
  QueryFamilyRow odd;
  odd.backend = "lib|odd*name";
  odd.samples = 300;
  odd.disagreements = 30;
  odd.measured = 120;
  odd.kinds = {{"early", 25, 8, 9.6e-8, 3.9e-4}, {"misses", 5, 10, 0.0, 0.0}};
  f.rows = {good, odd};
  return f;
}

TEST(QueryReport, RendersTheRankedRowsAndWhatEachGotWrong) {
  ExploreCheckSet set;
  set.seed = 7;
  const std::string md = query_sections_markdown({toi_family()}, set, "/nonexistent", true);
  ASSERT_NE(md.find("## Time of impact"), std::string::npos);
  EXPECT_EQ(md.find("## Distance and closest points"), std::string::npos);
  EXPECT_NE(md.find("`rbx explore --kind toi --seed 7 --count 300`"), std::string::npos);
  // Ranked as given: custom first, 0 %; the other 10 %, its name escaped.
  const size_t first = md.find("| 1 | **custom** | 0 % of 300 | 131 |");
  const size_t second = md.find("| 2 | **lib\\|odd\\*name** | 10 % of 300 | 120 |");
  ASSERT_NE(first, std::string::npos) << md;
  ASSERT_NE(second, std::string::npos) << md;
  EXPECT_LT(first, second);
  // What it got wrong, in its row: the early stops first, with where they stopped, then the
  // misses.
  EXPECT_NE(md.find("| early 25 (#8, apart by 9.6e-08 m, at most 0.00039 m); misses 5 (#10) |"),
            std::string::npos)
      << md;
  // Timed: the median and its range in µs; the other row untimed.
  EXPECT_NE(md.find("| 131 | 3e-10 / 0 / 0 | 0 | 9 (1.3-16) | - |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 120 | 0 / 0 / 0 | 0 | - | early 25"), std::string::npos) << md;
  // No figure was drawn in that folder: none is linked.
  EXPECT_EQ(md.find("!["), std::string::npos);
}

TEST(QueryReport, NothingWhenNoQueryRan) {
  EXPECT_EQ(query_sections_markdown({}, ExploreCheckSet{}, "", false), "");
  QueryFamily f = toi_family();
  // The figure's data: every row, its quantiles as given.
  f.rows[0].quantiles = {0.0, 1.0};
  const Json j = query_families_json({f}, ExploreCheckSet{});
  ASSERT_EQ(j["queries"].size(), 1u);
  EXPECT_EQ(j["queries"][0]["kind"], "toi");
  EXPECT_EQ(j["queries"][0]["backends"][0]["name"], "custom");
  EXPECT_EQ(j["queries"][0]["backends"][0]["quantiles_every_5"][1], 1.0);
  EXPECT_EQ(j["queries"][0]["backends"][0]["timed"], 40);
  EXPECT_EQ(j["queries"][0]["backends"][0]["time_s"], 9e-6);
}

}  // namespace
}  // namespace rbx
