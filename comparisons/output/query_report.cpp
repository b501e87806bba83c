#include "comparisons/output/query_report.h"

#include <filesystem>
#include <initializer_list>
#include <sstream>

#include "comparisons/output/scorecard.h"
#include "comparisons/output/table.h"
#include "engine/format.h"

namespace rbx {

namespace {

bool is_toi(const QueryFamily& f) { return f.error == "time_err"; }

// The explore kind the family's samples come from.
std::string kind_of(const QueryFamily& f) { return is_toi(f) ? "toi" : "distance"; }

std::string percent(long part, long whole) {
  if (whole <= 0) return "-";
  return fmt_num(100.0 * static_cast<double>(part) / static_cast<double>(whole), 3) + " %";
}

std::string figure(const QueryFamily& f, const std::string& report_dir, bool figures_ok) {
  const std::string file = "figures/query_" + kind_of(f) + ".png";
  if (!figures_ok || !std::filesystem::exists(std::filesystem::path(report_dir) / file)) return "";
  return "![" + kind_of(f) + " errors](" + md_url(file) + ")\n\n";
}

// What a row got wrong: each kind, how many samples, the first of them, and for an early stop or
// a late pass how far the pair was from touching at the row's time (median, largest).
std::string kinds_cell(const QueryFamilyRow& r) {
  if (r.kinds.empty()) return "-";
  std::string cell;
  for (const QueryFamilyRow::Kind& k : r.kinds) {
    cell += (cell.empty() ? "" : "; ") + k.name + " " + std::to_string(k.count) + " (#" +
            std::to_string(k.first);
    if (k.name == "early")
      cell += ", apart by " + fmt_num(k.separation_p50, 2) + " m, at most " +
              fmt_num(k.separation_max, 2) + " m";
    if (k.name == "late")
      cell += ", " + fmt_num(k.separation_p50, 2) + " m from touching, at most " +
              fmt_num(k.separation_max, 2) + " m";
    cell += ")";
  }
  return cell;
}

std::string ranked_table(const QueryFamily& f) {
  const bool toi = is_toi(f);
  Table t(
      {"rank", "backend", "disagrees", "measured",
       toi ? "time err p50 / p90 / p99 (of the interval)" : "distance err p50 / p90 / p99 (rel)",
       toi ? "right, yet over 1e-6 off (grazing)" : "witness err p50 / p90 (rel)",
       "time per query (µs)", "what it got wrong: samples (the first; at its time)"});
  int rank = 0;
  for (const QueryFamilyRow& r : f.rows) {
    const auto spread = [&](std::initializer_list<double> v) {
      if (!r.measured) return std::string("-");
      std::string out;
      for (double x : v) out += (out.empty() ? "" : " / ") + fmt_num(x, 2);
      return out;
    };
    t.add({std::to_string(++rank), "**" + md_escape(r.backend) + "**",
           percent(r.disagreements, r.samples) + " of " + std::to_string(r.samples),
           std::to_string(r.measured), spread({r.p50, r.p90, r.p99}),
           toi ? std::to_string(r.grazing) : spread({r.witness_p50, r.witness_p90}),
           r.timed ? fmt_num(r.time_s * 1e6, 3) + " (" + fmt_num(r.time_q25_s * 1e6, 2) + "-" +
                         fmt_num(r.time_q75_s * 1e6, 2) + ")"
                   : "-",
           kinds_cell(r)});
  }
  return t.markdown() + "\n";
}

std::string section(const QueryFamily& f, const ExploreCheckSet& set, const std::string& report_dir,
                    bool figures_ok) {
  std::ostringstream md;
  const std::string cmd = "rbx explore --kind " + kind_of(f) + " --seed " +
                          std::to_string(set.seed) + " --count " + std::to_string(f.count);
  if (is_toi(f)) {
    md << "## Time of impact\n\n"
       << "When two moving bodies first touch within an interval: " << f.count
       << " random separated pairs (`" << cmd
       << "`), each moving over 1 s head-on, obliquely, spinning, missing by a hair or "
          "grazing, every time-of-impact query (and its variants) against the `exact` oracle as "
          "`rbx toi` judges it (docs/time_of_impact.md). A disagreement: `misses` a touch, "
          "`false_contact` (a touch where the pair never touches), `early` or `late` (over 1e-6 "
          "of the interval before or after the touch; the pair's exact separation at the row's "
          "time says how far short it stopped or how deep it went), or a status `error`. A time "
          "at an instant the pair is within 1e-9 of its size of touching is right: a grazing "
          "touch closes so slowly that which instant is the touch is decided at the nanometre "
          "(`grazing`; in the figure, the errors past 1e-6 of a row that does not disagree). "
          "Time error: |t - t*| over the interval, over the samples where both touch "
          "(`measured`). Bullet's casts answer only a pair that does not turn.";
  } else {
    md << "## Distance and closest points\n\n"
       << "How far apart two separated bodies are, and their closest points: " << f.count
       << " random separated pairs (`" << cmd
       << "`; boxes, hulls of 4 to 2,000 points and slivers, size ratios to 1e3, gaps of 1e-9 to "
          "10 sizes), every distance query against the `exact` oracle as `rbx distance` judges "
          "it (docs/distance.md). A disagreement: `distance` or `witness` points off by more "
          "than 1e-6 of the true distance, `overlap` called on a separated pair, or a status "
          "`error`. Errors relative to the true distance, over the samples both answer apart "
          "(`measured`).";
  }
  md << " Time per query: on the first " << kQueryTimedSamples
     << " samples, each the median over interleaved rounds (docs/bench.md); the median over the "
        "samples and, in brackets, their 25-75 % range, which spans their sizes, not noise."
     << " Ranked by disagreement rate, then median error. The command writes each group's first "
        "sample as a scene (`rbx "
     << kind_of(f)
     << " SCENE` shows every row on it); what each query costs against the number of vertices: "
        "`rbx bench` (docs/bench.md).\n\n"
     << ranked_table(f) << figure(f, report_dir, figures_ok);
  return md.str();
}

}  // namespace

std::string query_sections_markdown(const std::vector<QueryFamily>& families,
                                    const ExploreCheckSet& set, const std::string& report_dir,
                                    bool figures_ok) {
  std::string md;
  for (const QueryFamily& f : families) md += section(f, set, report_dir, figures_ok);
  return md;
}

Json query_families_json(const std::vector<QueryFamily>& families, const ExploreCheckSet& set) {
  Json j = {{"seed", set.seed}, {"queries", Json::array()}};
  for (const QueryFamily& f : families) {
    Json q = {
        {"kind", kind_of(f)}, {"error", f.error}, {"count", f.count}, {"backends", Json::array()}};
    for (const QueryFamilyRow& r : f.rows)
      q["backends"].push_back({{"name", r.backend},
                               {"samples", r.samples},
                               {"disagreements", r.disagreements},
                               {"measured", r.measured},
                               {"quantiles_every_5", r.quantiles},
                               {"timed", r.timed},
                               {"time_s", r.time_s},
                               {"time_q25_s", r.time_q25_s},
                               {"time_q75_s", r.time_q75_s}});
    j["queries"].push_back(q);
  }
  return j;
}

}  // namespace rbx
