// The scorecard that opens report.md: one row per backend and scene family (scenes run, how many
// within tolerance, median and worst error against the truth, median run time per step or
// query), then the measured causes of each backend's failures, one line each, with the scenes.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "engine/scene.h"

namespace rbx {

/// The file-name slug of a scene in a report: FAMILY_STEM (figures, replay pages).
std::string scene_slug(const std::string& family, const std::string& file);

/// Text safe in Markdown (table cells and link text): \ ` * _ [ ] < > | # escaped.
std::string md_escape(const std::string& s);

/// The scorecard in Markdown. `backends` in the column order of the report; scenes link to
/// `views/SLUG.html` when `views` is true.
std::string scorecard_markdown(const std::vector<Scene>& scenes,
                               const std::vector<SceneEvaluation>& evs,
                               const std::vector<std::string>& backends, bool views);

/// The contact query times in Markdown: per backend, the median over the scenes' queries of the
/// time per query with the library's shapes built in the query (as the backend runs), with them
/// prebuilt (its "prebuilt" variant, where it has one), and the difference, the cost of
/// building them. Empty when no contact query ran.
std::string query_time_markdown(const std::vector<SceneEvaluation>& evs,
                                const std::vector<std::string>& backends);

}  // namespace rbx
