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

void print_stated(std::ostream& out, const StatedCheck& c, const std::string& block) {
  if (c.stated.empty()) return;
  auto names = [](const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& n : v) s += (s.empty() ? "" : ", ") + n;
    return s.empty() ? std::string("none") : s;
  };
  out << "\n"
      << block << " states " << c.stated << " for the first pair: met by " << names(c.met)
      << "; missed by " << names(c.missed) << "\n";
  if (!c.excused.empty()) out << "  " << c.excused << ": a known failure ([expect] says why)\n";
  if (!c.failing.empty())
    out << "  the scene fails: " << names(c.failing) << " (bound by [expect]) missed it\n";
}

}  // namespace rbx
