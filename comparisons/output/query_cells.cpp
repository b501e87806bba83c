#include "comparisons/output/query_cells.h"

#include "engine/format.h"

namespace rbx {

std::string mark_cell(const std::string& mark) {
  return mark == "disagrees" ? "✗" : mark == "deviates" ? "~" : "";
}

std::vector<std::string> timing_cells(const Timing& t, bool answered) {
  const bool timed = t.rounds > 0;
  return {timed ? fmt_num(t.median_s * 1e6, 3) : "-",
          timed ? fmt_num(t.q25_s * 1e6, 3) + "-" + fmt_num(t.q75_s * 1e6, 3) : "-",
          answered ? fmt_num(t.cold_s * 1e6, 3) : "-"};
}

const char* const kQueryTimingNote =
    "time: per query, the median over rounds of repeated calls (warmed up, backends "
    "interleaved; docs/bench.md) with its 25-75 % range; the cold call is the first, which "
    "gave the answer, timed alone\n";

}  // namespace rbx
