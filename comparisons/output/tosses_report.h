// The report's "Real impacts" section from the tosses study (comparisons/eval/tosses.h).
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/tosses.h"
#include "comparisons/output/table.h"

namespace rbx {

/// The results table, best first (`markdown`: status cells carry the message).
Table toss_results_table(const std::vector<BackendTosses>& rs, bool markdown);

/// Runs the tosses data set in folder `dir` (test.csv[.gz] with params.json) through every
/// dynamics backend (or those named in `backend_list`), at the stored and at the published
/// parameters; writes tosses.json, tosses_per_toss.csv and tosses_traj.csv into `out_dir`,
/// the figures into out_dir/figures (through comparisons/output/tosses_plots.py when python3 is
/// there) and returns the report's "Real impacts" markdown section. `threads`: as
/// evaluate_tosses.
std::string tosses_report_section(const std::string& dir, const std::string& out_dir,
                                  const std::string& backend_list, int threads = 0);

}  // namespace rbx
