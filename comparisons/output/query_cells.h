// The cells and the timing note every per-pair query table shares (rbx contacts, rbx distance,
// rbx toi), so the three say the same thing the same way.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "comparisons/eval/stated_check.h"
#include "comparisons/eval/timing.h"

namespace rbx {

/// A verdict's mark as a cell: "✗" (disagrees), "~" (deviates), or empty.
std::string mark_cell(const std::string& mark);

/// The three timing cells of a query's row: time (µs, the median), its 25-75 % range, and the
/// cold call (µs); "-" where it was not timed, and the cold call "-" when `answered` is false
/// (an unsupported query made no call).
std::vector<std::string> timing_cells(const Timing& t, bool answered = true);

/// The lines on the first pair's stated answer (`block`: "[expect.distance]" or "[expect.toi]"),
/// nothing when the scene states none: who meets it, who misses it, and whether the scene fails.
void print_stated(std::ostream& out, const StatedCheck& c, const std::string& block);

/// The note under a query table on what its times are.
extern const char* const kQueryTimingNote;

}  // namespace rbx
