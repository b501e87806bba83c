// The accuracy report's files (`rbx report`): details.md, results.json, metrics.csv,
// error_vs_runtime.csv, stability.csv and the figures, from the scenes' evaluations.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// World geometry of the bodies at t = 0 ({name, vertices, triangles} per body; empty when a
/// body has more than 2,000 vertices), for the report's contact pictures.
Json geometry_json(const Scene& scene);

/// Backends that appear anywhere in the evaluations, in registry order (the report's columns).
std::vector<std::string> report_columns(const std::vector<SceneEvaluation>& evs);

/// The error-against-run-time figures that exist in `report_dir`/figures, linked (when
/// `figures_ok` is false, why they are not there).
std::string error_vs_runtime_markdown(const std::vector<SceneEvaluation>& evs,
                                      const std::string& report_dir, bool figures_ok,
                                      const std::string& figures_msg);

/// The solver-budget table: per backend and family, the smallest budget that reaches the
/// backend's own converged error (comparisons/eval/budgets.h), with each backend's budget
/// named; "" when no scene has budget points.
std::string solver_budgets_markdown(const std::vector<SceneEvaluation>& evs);

/// details.md: the scorecard with every failing scene named, the summary of every scene for
/// every backend, contact phase, who disagrees and why, contact query time, solver budgets,
/// stability, contact laws, every ensemble's table (predictability) and every scene's detail.
/// `figures_ok` and `views_ok` say whether the figures (in `report_dir`) and replay pages were
/// written; `timing_budget_s`, the run's HarnessOptions::timing_budget_s (query_time_markdown).
std::string report_details_markdown(const std::vector<Scene>& scenes,
                                    const std::vector<SceneEvaluation>& evs,
                                    const std::string& report_dir, bool figures_ok, bool views_ok,
                                    double timing_budget_s = HarnessOptions{}.timing_budget_s);

/// results.json, metrics.csv, error_vs_runtime.csv and stability.csv into `dir`.
void write_report_tables(const std::string& dir, const std::vector<Scene>& scenes,
                         const std::vector<SceneEvaluation>& evs);

/// The report's figures into dir/figures through comparisons/output/plots.py and Debian's
/// python3, drawn by `jobs` processes; false with `message` set when they could not be drawn.
bool draw_report_figures(const std::string& dir, int jobs, std::string& message);

}  // namespace rbx
