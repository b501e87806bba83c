#include "comparisons/output/report_pages.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>

#include "comparisons/output/backend_style.h"
#include "comparisons/output/law_report.h"
#include "comparisons/output/markdown_html.h"
#include "comparisons/output/predictability_report.h"
#include "comparisons/output/query_report.h"
#include "comparisons/output/report_writer.h"
#include "comparisons/output/scorecard.h"
#include "comparisons/output/table.h"
#include "comparisons/scene/scene_file.h"

namespace rbx {

namespace {

namespace fs = std::filesystem;

// A row's best run time: the library's prebuilt variant where it has one (how a user holding
// the shapes runs it), else the time as it runs; negative when the row has no time.
double best_time(const ScoreRow& r, bool& prebuilt) {
  prebuilt = false;
  if (r.time.empty()) return -1.0;
  const double t = median_of(r.time);
  if (!r.prebuilt.empty() && median_of(r.prebuilt) < t) {
    prebuilt = true;
    return median_of(r.prebuilt);
  }
  return t;
}

std::string short_measure(Measure m) {
  switch (m) {
    case Measure::Contact:
      return "contacts";
    case Measure::Mass:
      return "mass";
    case Measure::Dynamics:
      break;
  }
  return "dynamics";
}

// Explore's families in the report: pseudo-scene, title, and the errors shown (metric stem,
// column).
struct ExploreFamily {
  const char* scene;
  const char* title;
  std::vector<std::pair<std::string, std::string>> errors;
};
const std::vector<ExploreFamily>& explore_families() {
  static const std::vector<ExploreFamily> families = {
      {"explore/contact",
       "contact pairs",
       {{"normal_err_deg", "normal error (deg) p50 / p90"},
        {"depth_err_rel", "depth error / smaller size p50 / p90"}}},
      {"explore/distance",
       "separated pairs (distance)",
       {{"distance_err_rel", "distance error / true distance p50 / p90"},
        {"witness_err_rel", "witness points' error / true distance p50 / p90"}}},
      {"explore/toi",
       "moving pairs (time of impact)",
       {{"time_err", "first touch's error / interval p50 / p90"}}},
      {"explore/impact", "impacts", {{"velocity_err_ke", "velocity error (KE norm) p50 / p90"}}},
      {"explore/landing",
       "landings with friction",
       {{"position_err_m", "position at rest error (m) p50 / p90"},
        {"turn_rad", "turn (rad) p50 / p90"}}},
      {"explore/slide",
       "slides on floors and inclines",
       {{"position_err_m", "position at rest error (m) p50 / p90"},
        {"rest_time_err_s", "time to rest error (s) p50 / p90"},
        {"turn_rad", "turn (rad) p50 / p90"}}},
      {"explore/tunnel",
       "fast projectiles at thin walls",
       {{"velocity_err_ke", "velocity error (KE norm) p50 / p90"}}}};
  return families;
}

// One family's metrics: backend -> metric -> value.
std::map<std::string, std::map<std::string, double>> family_metrics(
    const std::vector<ExploreCheckMetric>& metrics, const std::string& scene) {
  std::map<std::string, std::map<std::string, double>> by;
  for (const ExploreCheckMetric& m : metrics)
    if (m.scene == scene) by[m.metric.backend][m.metric.name] = m.metric.value;
  return by;
}

// What the samples are and what a disagreement is.
std::string explore_intro(const ExploreCheckSet& set) {
  std::ostringstream md;
  md << "What no scene of the library shows: `rbx explore`'s fixed samples (seed " << set.seed
     << "; the ones `rbx check` compares), " << set.contact
     << " random convex pairs against the `exact` oracle, " << set.distance
     << " random separated pairs (gaps of 1e-9 to 10 sizes) whose distance and closest points "
        "each distance query gives against the oracle's, "
     << set.toi
     << " random separated pairs set moving over an interval (head-on, oblique, spinning, "
        "missing by a hair, grazing) whose first touch each time-of-impact query gives against "
        "the oracle's (docs/time_of_impact.md), "
     << set.impact << " random vertex-on-face impacts at a random phase, " << set.landing
     << " random landings of a box sliding on a floor with friction (any direction, speed, mu "
        "and yaw), "
     << set.slide
     << " random slides of a box resting on a floor or an incline (launched along it or left "
        "at rest) and "
     << set.tunnel
     << " random fast projectiles at thin walls (up to 20 times the wall per step), against "
        "their closed forms. "
        "*Disagreement*: a sample a backend answers clearly wrong (normal > 1°, depth > 1 % of "
        "the smaller body, a distance or its points off by more than 1e-6 of the true distance "
        "(docs/distance.md), a first touch more than 1e-6 of the interval off, velocity error > "
        "0.1 %, a landing or slide at rest more than 1 mm "
        "from where Coulomb's law puts it or turned by more than 1e-3 rad, a slide coming to rest "
        "more than 3 ms off its time, a projectile through or into its wall, a missed or false "
        "contact, an error). Errors are the median and 90th percentile over the samples where "
        "both touch. `rbx explore` shrinks every disagreement to a scene.\n\n";
  return md.str();
}

// Explore's fixed samples at a glance: one table, a row per backend and a column per family,
// each cell its disagreement rate (the errors are in details.md).
std::string explore_markdown(const std::vector<ExploreCheckMetric>& metrics,
                             const ExploreCheckSet& set) {
  if (metrics.empty()) return "";
  std::ostringstream md;
  md << "## Random poses and impacts\n\n"
     << explore_intro(set)
     << "Each cell: the share of the family's samples the backend disagrees on; the median and "
        "90th percentile of each error are in details.md. The separated and the moving pairs "
        "have sections of their own (below: distance, time of impact).\n\n";
  std::vector<std::string> header = {"backend"}, order;
  std::map<std::string, std::map<std::string, double>> rate;  // backend -> family -> rate
  for (const ExploreFamily& f : explore_families()) {
    if (f.scene == std::string("explore/distance") || f.scene == std::string("explore/toi"))
      continue;  // their own sections (query_report.h)
    const auto by = family_metrics(metrics, f.scene);
    if (by.empty()) continue;
    header.push_back(f.title);
    for (const auto& [b, v] : by) {
      if (std::find(order.begin(), order.end(), b) == order.end()) order.push_back(b);
      rate[b][f.title] = v.at("disagreement_rate_err");
    }
  }
  std::vector<std::string> names;
  for (const Backend& b : backends())
    if (rate.count(b.name)) names.push_back(b.name);
  for (const std::string& b : order)
    if (std::find(names.begin(), names.end(), b) == names.end()) names.push_back(b);
  Table t(header);
  for (const std::string& b : names) {
    std::vector<std::string> row = {"**" + md_escape(b) + "**"};
    for (size_t k = 1; k < header.size(); ++k)
      row.push_back(rate[b].count(header[k]) ? fmt_num(100 * rate[b][header[k]], 3) + " %"
                                             : std::string("-"));
    t.add(row);
  }
  md << t.markdown() << "\n";
  return md.str();
}

}  // namespace

// Per group of the scorecard: the custom engine, and beside it the most accurate library (the
// first ranked that is neither an engine nor the oracle) and the fastest library, each with what
// it costs in the other currency.
std::string glance_markdown(const std::vector<ScoreRow>& rows) {
  Table t({"family", "custom: error, within tolerance, time", "most accurate library",
           "its error, within tolerance, time", "fastest library",
           "its time, error, within tolerance"});
  const auto library = [](const ScoreRow& r) {
    return r.backend != "exact" && r.backend.rfind("custom", 0) != 0;
  };
  for (size_t k = 0; k < rows.size();) {
    size_t end = k;
    while (end < rows.size() && rows[end].family == rows[k].family &&
           rows[end].measure == rows[k].measure)
      ++end;
    const ScoreRow *engine = nullptr, *best = nullptr, *fastest = nullptr;
    double fastest_t = 0.0;
    bool fastest_pre = false;
    // Timed runs of the libraries that ran the most (every timed scene of the family).
    size_t most_timed = 0;
    for (size_t r = k; r < end; ++r)
      if (library(rows[r])) most_timed = std::max(most_timed, rows[r].time.size());
    for (size_t r = k; r < end; ++r) {
      const ScoreRow& row = rows[r];
      if (row.backend == "custom") engine = &row;
      if (!library(row)) continue;
      if (!best && !row.error.empty()) best = &row;
      bool pre = false;
      const double tr = best_time(row, pre);
      if (tr >= 0 && row.time.size() == most_timed && (!fastest || tr < fastest_t))
        fastest = &row, fastest_t = tr, fastest_pre = pre;
    }
    const std::string unit = rows[k].measure == Measure::Contact ? " µs/query" : " µs/step";
    const auto within = [](const ScoreRow& r) {
      return std::to_string(r.within) + " of " + std::to_string(r.run);
    };
    const auto costs = [&](const ScoreRow* r) {
      return r ? r->median_text() + ", " + within(*r) + ", " + r->time_text() : std::string("-");
    };
    t.add({md_escape(rows[k].family) + " (" + short_measure(rows[k].measure) + ")", costs(engine),
           best ? "**" + md_escape(best->backend) + "**" : "-", costs(best),
           fastest ? "**" + md_escape(fastest->backend) + "**" : "-",
           fastest ? fmt_num(fastest_t * 1e6, 3) + unit + (fastest_pre ? " (prebuilt)" : "") +
                         ", " + fastest->median_text() + ", " + within(*fastest)
                   : "-"});
    k = end;
  }
  std::ostringstream md;
  md << "## At a glance\n\n"
        "Per scene family, the custom engine, and beside it the most accurate library (the first "
        "library of the family's ranked table below) and the fastest library (median run time; "
        "its prebuilt-shape variant where that is faster, an answer \"touching, no normal\" timed "
        "like any), each with what it costs in the other currency. Errors: contacts, normal "
        "angle (deg) / depth error (m); dynamics, post-impact velocity error relative to the "
        "motion (kinetic-energy norm; 0.001 is 0.1 %); mass, relative error. (n): the scenes "
        "with a truth to compare with. The fastest is chosen among the libraries that ran every "
        "timed scene of the family, so that one median does not come from fewer, smaller "
        "scenes.\n\n"
     << t.markdown() << "\n";
  return md.str();
}

std::string explore_details_markdown(const std::vector<ExploreCheckMetric>& metrics,
                                     const ExploreCheckSet& set) {
  if (metrics.empty()) return "";
  std::ostringstream md;
  md << "## Random poses and impacts\n\n"
     << explore_intro(set) << "Per family, backends by their disagreement rate.\n\n";
  for (const ExploreFamily& f : explore_families()) {
    auto by = family_metrics(metrics, f.scene);
    if (by.empty()) continue;
    std::vector<std::string> names;
    for (const auto& [b, v] : by) names.push_back(b);
    std::stable_sort(names.begin(), names.end(), [&](const std::string& a, const std::string& b) {
      return by[a]["disagreement_rate_err"] < by[b]["disagreement_rate_err"];
    });
    std::vector<std::string> header = {"backend", "disagreements"};
    for (const auto& e : f.errors) header.push_back(e.second);
    Table t(header);
    for (const std::string& b : names) {
      std::vector<std::string> row = {"**" + md_escape(b) + "**",
                                      fmt_num(100 * by[b]["disagreement_rate_err"], 3) + " %"};
      for (const auto& e : f.errors)
        row.push_back(fmt_num(by[b][e.first + "_p50"], 2) + " / " +
                      fmt_num(by[b][e.first + "_p90"], 2));
      t.add(row);
    }
    md << "### " << f.title << "\n\n" << t.markdown() << "\n";
  }
  return md.str();
}

// What each backend of the report runs (the registry's one line): plain names are the libraries
// as their experts configure them, `-hull` the same hull input as the custom engine.
std::string backends_markdown(const std::vector<std::string>& names) {
  Table t({"backend", "what it runs"});
  for (const std::string& n : names)
    if (const Backend* b = find_backend(n))
      t.add({"**" + md_escape(n) + "**", md_escape(b->description)});
  return "## Backends\n\nPlain names are the libraries as their own experts configure them; "
         "`-hull`, the same convex hulls the custom engine gets; `custom-seed`, the seed "
         "document's algorithm; `exact`, the oracle (docs/backends.md: every setting "
         "and its measurement).\n\n" +
         t.markdown() + "\n";
}

std::string report_summary_markdown(const std::vector<Scene>& scenes,
                                    const std::vector<SceneEvaluation>& evs,
                                    const SummaryInputs& in) {
  const std::vector<std::string> cols = report_columns(evs);
  std::vector<FailureCause> causes;
  const std::vector<ScoreRow> rows = score_rows(scenes, evs, cols, &causes);
  std::ostringstream md;
  md << "# rbx accuracy report\n\n"
     << scenes.size() << " scenes through " << cols.size() << " backends in "
     << fmt_num(in.total_s, 3)
     << " s. Every number except run times is deterministic: the same scenes give the same "
        "report.\n\n"
        "As a page: [index.html](index.html), this summary with its figures and every scene "
        "one click away"
     << (in.views_ok ? " (its numbers and its 3-D replay)" : " (its numbers)")
     << ". Every table in full, and every scene's numbers: [details.md](details.md) "
        "([details.html](details.html)); as data: [metrics.csv](metrics.csv), "
        "[error_vs_runtime.csv](error_vs_runtime.csv), [stability.csv](stability.csv), "
        "[laws.csv](laws.csv), [results.json](results.json).\n\n";
  md << glance_markdown(rows);
  // The causes name one scene each here; details.md names every one.
  md << scorecard_matrix_markdown(rows) << causes_markdown(causes, true, in.views_ok);
  md << error_vs_runtime_markdown(evs, in.report_dir, in.figures_ok, in.figures_msg);
  md << contact_laws_markdown(scenes, evs, cols, in.report_dir, in.figures_ok);
  md << predictability_summary_markdown(scenes, evs, in.report_dir, in.figures_ok);
  md << explore_markdown(in.explore, in.explore_set);
  md << query_sections_markdown(in.queries, in.explore_set, in.report_dir, in.figures_ok);
  md << in.tosses;
  md << backends_markdown(cols);
  return md.str();
}

void write_report_pages(const std::string& dir, const std::vector<Scene>& scenes,
                        const std::vector<SceneEvaluation>& evs, const std::string& summary_md,
                        const std::string& details_md, bool views_ok) {
  // Which backends are outside tolerance on each scene, from the measured causes.
  std::vector<FailureCause> causes;
  score_rows(scenes, evs, report_columns(evs), &causes);
  std::map<std::string, std::vector<std::string>> outside;  // slug -> backends
  for (const FailureCause& f : causes)
    for (const SceneRef& s : f.scenes) {
      std::vector<std::string>& list = outside[s.slug];
      if (std::find(list.begin(), list.end(), f.backend) == list.end()) list.push_back(f.backend);
    }
  std::ostringstream body;
  // The colour key goes under the figures' heading (the page's top when there are none).
  std::string summary = markdown_to_html(summary_md);
  const size_t figures = summary.find("<h2 id=\"error-against-run-time\">");
  summary.insert(figures == std::string::npos ? 0 : summary.find('\n', figures) + 1,
                 backend_legend_html(report_columns(evs)));
  body << summary;
  body << "<h2 id=\"scenes\">Every scene</h2>\n<p>Each scene's numbers (every backend, every "
          "metric) are in details.html"
       << (views_ok ? "; its replay plays every backend's run side by side in 3-D" : "")
       << ".</p>\n";
  body << "<table>\n<thead><tr><th>scene</th><th>description</th><th>checks</th><th>outside "
          "tolerance</th><th>numbers</th><th>replay</th></tr></thead>\n<tbody>\n";
  for (size_t i = 0; i < scenes.size() && i < evs.size(); ++i) {
    const std::string name = evs[i].family + "/" + scenes[i].name;
    const std::string slug = scene_slug(evs[i].family, scenes[i].file);
    std::string checks, bad;
    for (const std::string& c : scenes[i].check_names()) checks += (checks.empty() ? "" : ", ") + c;
    for (const std::string& b : outside[slug]) bad += (bad.empty() ? "" : ", ") + b;
    // details.html's heading of the scene is its md_escape'd name: the same anchor.
    body << "<tr><td>" << html_escape(name) << "</td><td>" << html_escape(scenes[i].description)
         << "</td><td>" << html_escape(checks) << "</td><td>"
         << html_escape(bad.empty() ? "none" : bad) << "</td><td><a href=\"details.html#"
         << html_escape(heading_anchor(md_escape(name))) << "\">numbers</a></td><td>"
         << (views_ok
                 ? "<a href=\"" + html_escape(md_url("views/" + slug + ".html")) + "\">replay</a>"
                 : "-")
         << "</td></tr>\n";
  }
  body << "</tbody>\n</table>\n";
  write_text((fs::path(dir) / "index.html").string(), html_page("rbx accuracy report", body.str()));
  write_text((fs::path(dir) / "details.html").string(),
             html_page("rbx accuracy report: every table", markdown_to_html(details_md)));
}

}  // namespace rbx
