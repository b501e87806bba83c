#include "comparisons/output/distance_table.h"

#include "comparisons/output/query_cells.h"
#include "comparisons/output/table.h"
#include "engine/format.h"

namespace rbx {

namespace {

std::string answer(const DistanceResult& r) {
  if (r.status != Status::Ok) return "-";
  return r.overlapping ? "overlapping" : fmt_num(r.distance, 10);
}

}  // namespace

void print_distances(std::ostream& out, const DistanceComparison& c) {
  for (const DistancePair& p : c.pairs) {
    out << "\npair " << p.a << "-" << p.b << "; exact: " << answer(p.truth);
    if (!p.truth.overlapping && p.truth.status == Status::Ok) out << " (" << p.truth.message << ")";
    out << "\n";
    Table table({"backend", "status", "distance", "point on " + p.a, "point on " + p.b,
                 "distance err", "witness err", "mark", "time (µs)", "25-75 %", "cold call (µs)"});
    for (const DistanceRow& r : p.rows) {
      const bool points = r.result.status == Status::Ok && !r.result.overlapping;
      std::vector<std::string> cells = {
          r.backend,
          to_string(r.result.status),
          answer(r.result),
          points ? fmt_vec(r.result.point_a) : "-",
          points ? fmt_vec(r.result.point_b) : "-",
          r.verdict.comparable ? fmt_num(r.verdict.distance_err, 3) : "-",
          r.verdict.comparable ? fmt_num(r.verdict.witness_err, 3) : "-",
          mark_cell(r.verdict.mark)};
      for (std::string& c : timing_cells(r.timing, r.result.status != Status::Unsupported))
        cells.push_back(std::move(c));
      table.add(std::move(cells));
    }
    table.print(out);
    for (const DistanceRow& r : p.rows)
      if (!r.result.message.empty() && r.result.status != Status::Unsupported &&
          r.backend != "exact")
        out << "  " << r.backend << ": " << r.result.message << "\n";
    for (const DistanceRow& r : p.rows)
      if (!r.verdict.mark.empty())
        out << "  " << r.verdict.mark << ": " << r.backend << " on " << p.a << "-" << p.b << ": "
            << r.verdict.why << "\n";
  }
  if (c.pairs.empty()) {
    out << "no pair of bodies to measure (every body is static, or there is only one)\n";
    return;
  }
  print_stated(out, c.expect, "[expect.distance]");
  out << "\nerrors: relative to the true distance, at least 1e-8 of the pair's extent from the "
         "origin (round-off of the coordinates); witness err: how far the two points are from a "
         "closest pair (off their bodies, or apart by other than the distance), on the same scale; "
         "✗ over 1e-6, ~ over 1e-9 and beyond round-off (docs/distance.md)\n";
  out << kQueryTimingNote;
}

}  // namespace rbx
