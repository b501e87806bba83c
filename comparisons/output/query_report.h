// The report's sections on the distance and time-of-impact queries: per query, its backends
// ranked over explore's fixed samples, the spread of their errors as a figure, and what each got
// wrong, measured sample by sample (QueryFamily, comparisons/eval/explore_check.h).
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/explore_check.h"
#include "comparisons/eval/json_io.h"

namespace rbx {

/// report.md's "Distance and closest points" and "Time of impact" sections ("" when neither ran);
/// a figure is linked where figures/query_<kind>.png exists in `report_dir`.
std::string query_sections_markdown(const std::vector<QueryFamily>& families,
                                    const ExploreCheckSet& set, const std::string& report_dir,
                                    bool figures_ok);

/// queries.json, what plots.py draws the sections' figures from: per query, per backend, its
/// main error every 5 % over the samples it measured.
Json query_families_json(const std::vector<QueryFamily>& families, const ExploreCheckSet& set);

}  // namespace rbx
