// The whole scene library, once per test run: `rbx report --check` in-process. One run of every
// scene through every backend it needs gives both the regression check (every accuracy metric
// of every scene, of explore's fixed random samples and of the measured tosses, no worse than
// reports/baseline.json) and the report's size budgets (report.md, the summary, at most 300
// lines; results.json under 5 MB: the detail belongs in details.md and the CSV files).
// `rbx check` and `rbx report` themselves are run by the command-line tests on a few scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "comparisons/cli/commands.h"

#ifdef RBX_SANITIZE
// LeakSanitizer's suppressions for this test. ODE 0.16: one 80-byte block allocated inside ODE's
// self-threading implementation (dxtemplateThreadingImplementation) is reported once at the end
// of a whole library check. No single scene through `ode` or `ode-hull` reproduces it (each scene
// checked alone): the cause is not yet found. Only that ODE frame is suppressed; any other leak
// still fails.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:dxtemplateThreadingImplementation\n";
}
#endif

namespace rbx {
namespace {

namespace fs = std::filesystem;

#ifdef RBX_SANITIZE
TEST(LibraryCheck, EveryMetricOfTheSceneFamiliesIsNoWorseThanTheBaseline) {
  // The sanitizer build checks the scene families only, without the external cases, the random
  // samples, the tosses and the report around them: those run the same contact and dynamics
  // code as the contact scenes and explore's and the tosses' own tests, at many times the cost
  // under the sanitizers.
  ReportOptions opt;
  for (const char* family :
       {"analytic", "contact", "friction", "many", "mass", "real", "resting", "seed", "stress"})
    opt.inputs.push_back(std::string(RBX_SOURCE_DIR) + "/scenes/" + family);
  // Prints every changed metric under its scene and backend; 1 when any is worse.
  EXPECT_EQ(check_command(opt), 0);
}
#else
constexpr size_t kMaxSummaryLines = 300;
constexpr std::uintmax_t kMaxResultsBytes = 5'000'000;

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// "lines  heading" of each level-2 section of a Markdown text, longest first.
std::string section_lengths(const std::string& md) {
  std::vector<std::pair<size_t, std::string> > sections = {{0, "(before the first section)"}};
  std::istringstream in(md);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) sections.emplace_back(0, line.substr(3));
    ++sections.back().first;
  }
  std::sort(sections.rbegin(), sections.rend());
  std::ostringstream out;
  for (const auto& [n, heading] : sections) out << "  " << n << "  " << heading << "\n";
  return out.str();
}

TEST(LibraryCheck, EveryMetricIsNoWorseThanTheBaselineAndTheReportKeepsItsBudgets) {
  ReportOptions opt;
  opt.out = std::string(RBX_BINARY_DIR) + "/tests/full_report";
  opt.check = true;
  opt.quiet = true;
  // One call per contact query and main dynamics run: this test checks the report's answers and
  // its size, which timing repeats do not change (timings never fail the check); the report's
  // timed repeats are tested in harness_test.cpp.
  opt.timing_budget_s = 0.0;
  // Prints every changed metric under its scene and backend; 1 when any is worse.
  EXPECT_EQ(report_command(opt), 0);

  const fs::path out(opt.out);
  const std::string summary = read(out / "report.md");
  ASSERT_FALSE(summary.empty());
  const size_t lines = static_cast<size_t>(std::count(summary.begin(), summary.end(), '\n'));
  EXPECT_LE(lines, kMaxSummaryLines)
      << "report.md is the summary; its sections, longest first (move detail to details.md):\n"
      << section_lengths(summary);
  EXPECT_LT(fs::file_size(out / "results.json"), kMaxResultsBytes)
      << "results.json over its budget (docs/contract.md says what it leaves to the CSV files)";
}
#endif

}  // namespace
}  // namespace rbx
