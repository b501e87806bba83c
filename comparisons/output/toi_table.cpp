#include "comparisons/output/toi_table.h"

#include "comparisons/output/query_cells.h"
#include "comparisons/output/table.h"
#include "engine/format.h"

namespace rbx {

namespace {

std::string answer(const ToiResult& r) {
  if (r.status != Status::Ok) return "-";
  return r.hit ? fmt_num(r.fraction, 10) : "no touch";
}

}  // namespace

void print_tois(std::ostream& out, const ToiComparison& c) {
  out << "interval: " << fmt_num(c.interval, 6) << " s, each body at its velocity and angular "
      << "velocity from its t = 0 pose\n";
  for (const ToiPair& p : c.pairs) {
    out << "\npair " << p.a << "-" << p.b << "; exact: " << answer(p.truth);
    if (p.truth.status != Status::Ok) out << " (" << to_string(p.truth.status) << ")";
    if (!p.truth.message.empty()) out << " (" << p.truth.message << ")";
    out << "\n";
    Table table({"backend", "status", "touch at", "point", "normal", "time err", "normal err (°)",
                 "point err", "mark", "time (µs)", "25-75 %", "cold call (µs)"});
    for (const ToiRow& r : p.rows) {
      const bool located = r.result.status == Status::Ok && r.result.hit && r.result.located;
      std::vector<std::string> cells = {
          r.backend,
          to_string(r.result.status),
          answer(r.result),
          located ? fmt_vec(r.result.point) : "-",
          located ? fmt_vec(r.result.normal) : "-",
          r.verdict.comparable ? fmt_num(r.verdict.time_err, 3) : "-",
          r.verdict.located ? fmt_num(r.verdict.normal_err_deg, 3) : "-",
          r.verdict.located ? fmt_num(r.verdict.point_err_rel, 3) : "-",
          mark_cell(r.verdict.mark)};
      for (std::string& c : timing_cells(r.timing, r.result.status != Status::Unsupported))
        cells.push_back(std::move(c));
      table.add(std::move(cells));
    }
    table.print(out);
    for (const ToiRow& r : p.rows)
      if (!r.result.message.empty() && r.result.status != Status::Unsupported)
        out << "  " << r.backend << ": " << r.result.message << "\n";
    for (const ToiRow& r : p.rows)
      if (!r.verdict.mark.empty())
        out << "  " << r.verdict.mark << ": " << r.backend << " on " << p.a << "-" << p.b << ": "
            << r.verdict.why << "\n";
  }
  if (c.pairs.empty()) {
    out << "no pair of bodies to measure (every body is static, or there is only one)\n";
    return;
  }
  print_stated(out, c.expect, "[expect.toi]");
  out << "\ntouch at: the first touch, as a fraction of the interval; time err: its distance from "
         "the oracle's; ✗ over 1e-6, ~ over 1e-9 (docs/time_of_impact.md). normal err: the angle "
         "to the oracle's normal (at an edge or a corner many are right); point err: how far the "
         "point is from either body at the oracle's time, over the pair's size\n";
  out << kQueryTimingNote;
}

}  // namespace rbx
