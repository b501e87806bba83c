// The accuracy report's files (`rbx report`): report.md, results.json, metrics.csv, sweep.csv,
// stability.csv and the figures, from the scenes' evaluations.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/json_io.h"
#include "engine/scene.h"

namespace rbx {

/// World geometry of the bodies at t = 0 ({name, vertices, triangles} per body; empty when a
/// body has more than 2,000 vertices), for the report's contact pictures.
Json geometry_json(const Scene& scene);

/// report.md: scorecard, summary, contact phase, who disagrees and why, error against run time,
/// stability and every scene's detail. `total_s` is the evaluation's wall time; `figures_ok` and
/// `figures_msg` say whether the figures were drawn; `views_ok` whether the replay pages were.
std::string report_markdown(const std::vector<Scene>& scenes,
                            const std::vector<SceneEvaluation>& evs, double total_s,
                            bool figures_ok, const std::string& figures_msg, bool views_ok);

/// results.json, metrics.csv, sweep.csv and stability.csv into `dir`.
void write_report_tables(const std::string& dir, const std::vector<Scene>& scenes,
                         const std::vector<SceneEvaluation>& evs);

/// The report's figures into dir/figures through comparisons/output/plots.py and Debian's
/// python3; false with `message` set when they could not be drawn.
bool draw_report_figures(const std::string& dir, std::string& message);

}  // namespace rbx
