// `rbx bench`: times the bench table (comparisons/eval/bench_cases.h) and writes its pages
// (comparisons/output/perf_report.h) into --out (default reports/latest, beside `rbx report`'s
// files, which that command carries over when it replaces the folder). Without --out,
// reports/perf.md (the path docs/contract.md names) gets a copy of perf.md whose figure links point
// into latest/.
#include <filesystem>
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/bench_cases.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/output/perf_report.h"
#include "comparisons/scene/repo_path.h"
#include "engine/format.h"

namespace rbx {

int bench_command(const BenchOptions& opt) {
  const BenchPlan plan = bench_plan(opt.quick);
  const std::string out = opt.out.empty() ? default_repo_path("reports/latest") : opt.out;
  Stopwatch clock;
  const BenchResults results = run_bench(plan);
  const std::vector<PerfGoal> goals = perf_goals(plan, results);
  write_perf_pages(plan, results, goals, clock.seconds(), out, opt.out.empty());
  std::cout << "bench: " << (std::filesystem::path(out) / "perf.md").string() << " ("
            << results.cases << " cases, " << fmt_num(clock.seconds(), 3) << " s)\n";
  for (const PerfGoal& g : goals)
    std::cout << "  " << (g.met ? "met    " : "NOT MET") << "  " << g.goal << ": " << g.measured
              << "\n";
  return 0;
}

}  // namespace rbx
