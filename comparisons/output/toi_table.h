// `rbx toi`'s text: one table per pair, every backend's time of impact against the oracle.
#pragma once

#include <ostream>

#include "comparisons/eval/toi_query.h"

namespace rbx {

/// The comparison as text: per pair the oracle's answer, one row per backend (status, time as a
/// fraction of the interval, point, normal, errors against exact, mark, run time), each
/// backend's message and the marks' reasons.
void print_tois(std::ostream& out, const ToiComparison& c);

}  // namespace rbx
