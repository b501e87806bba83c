// `rbx distance`'s text: one table per pair, every backend's distance query against the oracle.
#pragma once

#include <ostream>

#include "comparisons/eval/distance_query.h"

namespace rbx {

/// The comparison as text: per pair the oracle's distance and closest features, one row per
/// backend (status, distance, witness points, errors against exact, mark, time), each backend's
/// message and the marks' reasons.
void print_distances(std::ostream& out, const DistanceComparison& c);

}  // namespace rbx
