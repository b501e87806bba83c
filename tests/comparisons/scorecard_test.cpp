// The scorecard at a glance (output/scorecard.h): report.md's one table, a row per backend and a
// column per family and measure, each cell the rank, the median error and the scenes within
// tolerance, in the unit of its column.
#include "comparisons/output/scorecard.h"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "comparisons/output/report_pages.h"

namespace rbx {
namespace {

ScoreRow row(const std::string& backend, const std::string& family, Measure m,
             std::vector<double> error, int run, int within) {
  ScoreRow r;
  r.backend = backend;
  r.family = family;
  r.measure = m;
  r.error = std::move(error);
  if (m == Measure::Contact) r.depth_error.assign(r.error.size(), 1e-3);
  r.run = run;
  r.within = within;
  return r;
}

// The table's line that starts with `start`.
std::string line_of(const std::string& md, const std::string& start) {
  std::istringstream in(md);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(start, 0) == 0) return line;
  return "";
}

TEST(ScorecardMatrix, OneRowPerBackendInRegistryOrderAndEachCellInItsColumnsUnit) {
  // Rows as score_rows ranks them: per group, best first. `bullet` ran no mass scene; the
  // registry lists `custom` before `bullet` whatever the ranks.
  const std::vector<ScoreRow> rows = {
      row("bullet", "contact", Measure::Contact, {0.5, 1.5}, 2, 1),
      row("custom", "contact", Measure::Contact, {2.0, 4.0}, 2, 2),
      row("custom", "seed", Measure::Dynamics, {1e-15}, 3, 3),
      row("bullet", "seed", Measure::Dynamics, {0.25}, 3, 0),
      row("custom", "mass", Measure::Mass, {}, 1, 1),
  };
  const std::string md = scorecard_matrix_markdown(rows);
  EXPECT_NE(md.find("## Scorecard"), std::string::npos);
  EXPECT_NE(md.find("| backend | contact (contacts) | seed (dynamics) | mass (mass) |"),
            std::string::npos)
      << md;
  EXPECT_LT(md.find("| **custom** |"), md.find("| **bullet** |"));
  // custom: second on contacts (median 3 degrees, 1 mm), first on seed, no truth on mass.
  EXPECT_EQ(line_of(md, "| **custom** |"),
            "| **custom** | #2 3° / 0.001, 2/2 | #1 1e-15, 3/3 | #1 -, 1/1 |")
      << md;
  EXPECT_EQ(line_of(md, "| **bullet** |"), "| **bullet** | #1 1° / 0.001, 1/2 | #2 0.25, 0/3 | · |")
      << md;
  // The full ranked tables are one link away.
  EXPECT_NE(md.find("[details.md](details.md) (its section *Scorecard*)"), std::string::npos);
  // A backend name is text, not markup.
  const std::string odd =
      scorecard_matrix_markdown({row("my_*x*", "seed", Measure::Dynamics, {0.1}, 1, 1)});
  EXPECT_NE(odd.find("| **my\\_\\*x\\*** | #1 0.1, 1/1 |"), std::string::npos) << odd;
}

TEST(AtAGlance, TheEngineThenTheMostAccurateAndTheFastestLibrary) {
  // Ranked as score_rows ranks them. fcl is the most accurate library, ode the fastest of those
  // that ran every timed scene (libccd-mpr is faster but timed on one scene of two: a median of
  // fewer, smaller scenes); the engines and the oracle are never the libraries named.
  const auto timed = [](ScoreRow r, std::vector<double> t) {
    r.time = std::move(t);
    return r;
  };
  const std::vector<ScoreRow> rows = {
      timed(row("custom", "contact", Measure::Contact, {0.0, 0.0}, 2, 2), {2e-6, 2e-6}),
      timed(row("exact", "contact", Measure::Contact, {0.0, 0.0}, 2, 2), {1e-7, 1e-7}),
      timed(row("fcl", "contact", Measure::Contact, {1.0, 1.0}, 2, 2), {3e-6, 3e-6}),
      timed(row("ode", "contact", Measure::Contact, {2.0, 2.0}, 2, 1), {1e-6, 1e-6}),
      timed(row("libccd-mpr", "contact", Measure::Contact, {3.0}, 2, 1), {2e-7}),
      timed(row("custom-seed", "seed", Measure::Dynamics, {0.0}, 1, 1), {1e-7}),
      timed(row("bullet", "seed", Measure::Dynamics, {0.5}, 1, 0), {4e-6}),
  };
  const std::string md = glance_markdown(rows);
  EXPECT_EQ(
      line_of(md, "| contact (contacts) |"),
      "| contact (contacts) | 0° / 0.001 (2), 2 of 2, 2 µs/query | **fcl** | 1° / 0.001 (2), 2 "
      "of 2, 3 µs/query | **ode** | 1 µs/query, 2° / 0.001 (2), 1 of 2 |")
      << md;
  // No custom row in a family: a dash; the seed's own algorithm is an engine, not a library.
  EXPECT_EQ(line_of(md, "| seed (dynamics) |"),
            "| seed (dynamics) | - | **bullet** | 0.5 (1), 0 of 1, 4 µs/step | **bullet** | 4 "
            "µs/step, 0.5 (1), 0 of 1 |")
      << md;
}

}  // namespace
}  // namespace rbx
