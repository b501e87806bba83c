// `rbx bench`'s pages: the goals (comparisons/eval/bench_goals.h) and perf.md, perf.json,
// perf.csv and figures/perf_*.{png,svg} (comparisons/output/bench_plots.py, matplotlib).
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/bench_goals.h"

namespace rbx {

/// Writes perf.md, perf.json, perf.csv and the figures into `out`, each file built in a
/// temporary folder and moved in (other files there, such as `rbx report`'s, are kept). With
/// `contract_copy`, reports/perf.md (the path docs/contract.md names, beside `out`) gets a copy of
/// perf.md whose figure links point into `out`'s folder name "latest/". `timing_s` is the wall
/// time of the timing, written into perf.md.
void write_perf_pages(const BenchPlan& plan, const BenchResults& results,
                      const std::vector<PerfGoal>& goals, double timing_s, const std::string& out,
                      bool contract_copy);

}  // namespace rbx
