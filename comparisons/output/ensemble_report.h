// What `rbx ensemble` prints: the nudges, the input spread and, per backend, the spread of the
// final states, its amplification, the contact sequences and clusters, and the step test.
#pragma once

#include <ostream>
#include <string>

#include "comparisons/eval/ensemble.h"

namespace rbx {

/// The ensemble as readable tables (the most frequent contact sequences of each backend too).
void print_ensemble(std::ostream& out, const EnsembleResult& r);

/// Draws DIR/ensemble_scatter.png (the copies' final positions per backend) and, when the JSON
/// has nudge sizes, DIR/ensemble_spread.png, from DIR/ensemble.json (matplotlib through
/// /usr/bin/python3; its output in DIR/figures.log). False when they could not be drawn.
bool draw_ensemble_figures(const std::string& dir);

}  // namespace rbx
