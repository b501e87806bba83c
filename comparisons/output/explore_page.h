// explore.md and the figure of an explore campaign.
#pragma once

#include <string>

#include "comparisons/eval/explore_summary.h"

namespace rbx {

/// explore.md of a campaign (every kind): the backends' rates and error percentiles, the phase
/// table (impact, landing, tunnel), the groups and their scenes; `have_figure` links
/// explore_errors.png.
std::string explore_markdown(const ExploreSummary& s, bool have_figure);

/// DIR/explore_errors.png from DIR/explore.json through comparisons/output/explore_plots.py and
/// Debian's python3 (its log in DIR/figures.log); false when it could not be drawn.
bool draw_explore_figure(const std::string& dir);

}  // namespace rbx
