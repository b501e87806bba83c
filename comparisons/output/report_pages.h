// The report a reader opens first: report.md, a summary of at most a few hundred lines (what
// answers "which backend is most accurate, which is fastest, at what cost"), and index.html, the
// same summary as a page with its figures inline and every scene one click away (its numbers in
// details.html, its 3-D replay in views/).
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/explore_check.h"
#include "comparisons/eval/harness.h"
#include "comparisons/output/scorecard.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// What the summary needs beside the evaluations.
struct SummaryInputs {
  std::string report_dir;   // where the report is written (figures/ in it)
  double total_s = 0.0;     // the evaluation's wall time
  bool figures_ok = false;  // the figures were drawn
  std::string figures_msg;  // why not, when they were not
  bool views_ok = false;    // the replay pages were written
  std::string tosses;       // the real tosses' sections (Markdown), "" when none
  /// Explore's fixed random samples (explore_check_metrics), empty when not run.
  std::vector<ExploreCheckMetric> explore;
  ExploreCheckSet explore_set;  // the sample set they come from
  /// Their distance and time-of-impact queries' sections (report.md's own sections).
  std::vector<QueryFamily> queries;
};

/// details.md's random poses and impacts: per explore family one table, backends by their
/// disagreement rate, with the median and 90th percentile of their errors ("" when not run).
std::string explore_details_markdown(const std::vector<ExploreCheckMetric>& metrics,
                                     const ExploreCheckSet& set);

/// report.md's At a glance, from the scorecard's ranked rows: per family the custom engine, the
/// most accurate library and the fastest library (among those that ran every timed scene of
/// the family), each with its error, scenes within tolerance and run time.
std::string glance_markdown(const std::vector<ScoreRow>& rows);

/// report.md: at a glance (glance_markdown), the ranked scorecard, the measured causes
/// of failures (one scene each), error against run time, random poses and impacts (explore's
/// fixed samples, when run), the distance and time-of-impact queries, the real tosses, and
/// links to the full tables.
std::string report_summary_markdown(const std::vector<Scene>& scenes,
                                    const std::vector<SceneEvaluation>& evs,
                                    const SummaryInputs& in);

/// index.html (the summary, then every scene: family, checks, backends outside tolerance,
/// links to its numbers and replay) and details.html (`details_md` as a page) into `dir`.
void write_report_pages(const std::string& dir, const std::vector<Scene>& scenes,
                        const std::vector<SceneEvaluation>& evs, const std::string& summary_md,
                        const std::string& details_md, bool views_ok);

}  // namespace rbx
