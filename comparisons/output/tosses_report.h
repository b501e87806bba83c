// The report's "Real impacts" section from the tosses study (comparisons/eval/tosses.h).
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/tosses.h"
#include "comparisons/output/table.h"

namespace rbx {

/// The results table, best first (`markdown`: status cells carry the message).
Table toss_results_table(const std::vector<BackendTosses>& rs, bool markdown);

/// Writes the study's files into `out_dir` (tosses.json, tosses_per_toss.csv,
/// tosses_error_time.csv, tosses_traj.csv, the picked tosses' replays in views/, the figures in
/// figures/ through comparisons/output/tosses_plots.py when python3 is there) and returns the
/// report's "Real impacts" markdown section ("" when no backend was tossed).
std::string tosses_report_section(const TossReportStudy& study, const std::string& out_dir);

}  // namespace rbx
