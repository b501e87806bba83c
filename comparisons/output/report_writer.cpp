// The accuracy report's files: report.md (scorecard, summary, contact phase, who disagrees and
// why, error against run time, stability, every scene's detail), results.json, the CSV tables
// and the figures drawn from them.
#include "comparisons/output/report_writer.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "comparisons/eval/budgets.h"
#include "comparisons/eval/contact_cause.h"
#include "comparisons/eval/trajectory.h"
#include "comparisons/output/figure_script.h"
#include "comparisons/output/law_report.h"
#include "comparisons/output/predictability_report.h"
#include "comparisons/output/report_why.h"
#include "comparisons/output/scorecard.h"
#include "comparisons/output/table.h"
#include "engine/format.h"

namespace fs = std::filesystem;

namespace rbx {

namespace {

const Metric* find_metric(const SceneEvaluation& ev, const std::string& backend,
                          const std::string& name) {
  for (const Metric& m : ev.metrics)
    if (m.backend == backend && m.name == name) return &m;
  return nullptr;
}

// The headline cell of a scene for one backend, and what it was measured against.
std::string headline(const SceneEvaluation& ev, const std::string& backend, std::string& against) {
  const BackendRun* run = ev.run_of(backend);
  if (!run) return "";
  if (run->status == Status::Unsupported) return "n/a";
  if (run->status == Status::Error || run->status == Status::Timeout) return to_string(run->status);
  std::string cell;
  if (run->status == Status::Touching) {
    cell = "touching, no normal";
  } else if (const Metric* t = find_metric(ev, backend, "touching_err"); t && t->value > 0) {
    cell = "wrong touch";
  } else if (const Metric* a = find_metric(ev, backend, "normal_err_deg")) {
    const Metric* d = find_metric(ev, backend, "depth_err");
    cell = fmt_num(a->value, 2) + "° / " + fmt_num(d ? d->value : 0.0, 2);
    against = a->against;
  } else if (const Metric* v = find_metric(ev, backend, "velocity_err_ke")) {
    cell = fmt_num(v->value, 2);
    against = v->against;
  } else if (find_metric(ev, backend, "inertia_err_rel")) {
    // Mass scenes: the worst relative inertia error over the bodies.
    double worst = 0.0;
    for (const Metric& m : ev.metrics)
      if (m.backend == backend && m.name == "inertia_err_rel") worst = std::max(worst, m.value);
    cell = "inertia " + fmt_num(worst, 2);
    against = "exact solid";
  } else if (!run->stability.empty()) {
    cell = run->stability;
  } else if (t) {
    cell = "0 (no contact)";
  } else {
    cell = "ok";
  }
  if (mentions_backend(ev.disagreements, backend))
    cell += " ✗";
  else if (mentions_backend(ev.deviations, backend))
    cell += " ~";
  // The engine under test on a documented limitation: marked by the same rule, and labelled.
  // The engine the known failure names ("custom" or "custom-seed", before its colon).
  if (ev.expect_known && backend == ev.known_failure.substr(0, ev.known_failure.find(':')))
    cell += " (known failure)";
  return cell;
}

// The headline of every scene for every backend, ✗ and ~ marked.
std::string summary_section(const std::vector<Scene>& scenes,
                            const std::vector<SceneEvaluation>& evs,
                            const std::vector<std::string>& cols, bool views_ok) {
  std::ostringstream md;
  md << "## Summary\n\n";
  md << "Headline error of each backend on each scene. Contact scenes: **normal angle (deg) / "
        "depth error (m)** of the deepest point against the closed form (`[expect]`) or the "
        "`exact` oracle. Dynamics scenes: **post-collision velocity error in the kinetic-energy "
        "norm** `sqrt(sum m|dv|^2 + dw.I.dw) / sqrt(2 E_ref)` against the closed form or the "
        "same backend at its finest time step. Stability-only scenes: the verdict. **✗** marks a "
        "backend that clearly disagrees with the closed form or `exact` (normal off by more than "
        "1°, depth by more than 1 % of the smaller body, or velocity error above 0.1 %); **~** "
        "one outside the scene's tolerance but within those bounds; `n/a`: the backend cannot "
        "serve the scene; blank: not run for this scene's checks.\n\n";
  std::vector<std::string> header = {"scene", "checks", "against"};
  header.insert(header.end(), cols.begin(), cols.end());
  Table summary(header);
  int marks = 0;
  for (size_t i = 0; i < evs.size(); ++i) {
    std::string against;
    std::vector<std::string> row = {md_escape(evs[i].family + "/" + scenes[i].name), "", ""};
    if (views_ok)
      row[0] = "[" + row[0] + "](" +
               md_url("views/" + scene_slug(evs[i].family, scenes[i].file) + ".html") + ")";
    std::string checks;
    for (const std::string& c : scenes[i].check_names()) checks += (checks.empty() ? "" : ", ") + c;
    row[1] = checks;
    for (const std::string& c : cols) {
      std::string a;
      row.push_back(headline(evs[i], c, a));
      if (row.back().find("✗") != std::string::npos) ++marks;
      if (against.empty() || against == a)
        against = a;
      else if (!a.empty() && a.rfind("self", 0) == 0 && against.rfind("self", 0) == 0)
        against = "self (finest dt)";
    }
    row[2] = against;
    if (!evs[i].expect_failures.empty())
      row[0] += evs[i].expect_known ? " [expect: known failure]" : " **[expect failed]**";
    summary.add(row);
  }
  md << summary.markdown() << "\n" << marks << " cells marked ✗.\n\n";

  return md.str();
}

// The impact scenes also run with first contact 1/3 and 2/3 of a step later.
std::string contact_phase_section(const std::vector<Scene>& scenes,
                                  const std::vector<SceneEvaluation>& evs,
                                  const std::vector<std::string>& cols) {
  std::ostringstream md;
  Table phases({"scene", "backend", "as written", "1/3 later", "2/3 later", "worst"});
  for (size_t i = 0; i < evs.size(); ++i)
    for (const std::string& c : cols) {
      const BackendRun* run = evs[i].run_of(c);
      if (!run || !run->contact_phase) continue;
      const ContactPhaseRow& p = *run->contact_phase;
      auto cell = [](const ContactPhaseCell& x) {
        if (x.error) return fmt_num(*x.error, 2);
        return x.failure.empty() ? std::string("-") : md_escape(x.failure);
      };
      phases.add({md_escape(evs[i].family + "/" + scenes[i].name), c, cell(p.written),
                  cell(p.one_third), cell(p.two_thirds), cell(p.worst)});
    }
  if (phases.size() > 0) {
    md << "## Contact phase\n\n";
    md << "Every analytic scene puts first contact exactly on a step boundary, at zero depth. "
          "Each impact with a closed form and neither gravity nor spin is also run with every "
          "moving body moved back along its velocity by 1/3 and 2/3 of a step (and one step "
          "more of duration), so first contact falls inside a step and the closed form is "
          "unchanged. Velocity error in the kinetic-energy norm; the summary's headline cell is "
          "the scene **as written**; `worst` is the largest of the three.\n\n";
    md << phases.markdown() << "\n";
  }
  return md.str();
}

// Disagreements, grouped by backend, then the why-list.
std::string disagreement_section(const std::vector<Scene>& scenes,
                                 const std::vector<SceneEvaluation>& evs,
                                 const std::vector<std::string>& cols) {
  std::ostringstream md;
  md << "## Who disagrees with the truth\n\n";
  std::map<std::string, std::vector<std::string>> by_backend;
  for (size_t i = 0; i < evs.size(); ++i)
    for (const std::string& d : evs[i].disagreements) {
      const std::string name = d.substr(0, d.find_first_of(" :"));
      by_backend[name].push_back(scenes[i].name + ": " + d.substr(name.size() + 1));
    }
  if (by_backend.empty()) md << "No backend disagrees with a closed form or the exact oracle.\n\n";
  for (const std::string& c : cols) {
    if (!by_backend.count(c)) continue;
    const auto& list = by_backend[c];
    md << "- **" << c << "** (" << list.size() << "): ";
    for (size_t k = 0; k < list.size() && k < 6; ++k) md << (k ? "; " : "") << list[k];
    if (list.size() > 6) md << "; and " << list.size() - 6 << " more (see the scene details)";
    md << "\n";
  }
  md << "\n" << why_markdown(scenes, evs, cols);

  return md.str();
}

// Every stability verdict, at the scene's step and along its own dt study.
std::string stability_section(const std::vector<Scene>& scenes,
                              const std::vector<SceneEvaluation>& evs) {
  std::ostringstream md;
  md << "## Stability\n\n";
  md << "Verdicts, worst first: **unstable** (non-finite state, energy gained beyond 1 %, "
        "tunnelling, a stopped run, momentum drift in a closed system, penetration past half a "
        "body), **sinks** (bodies more than 1 % of the smaller body inside each other in every "
        "sample of the last fifth of the run: \"at rest\"), **dissipative** (e = 1, no friction, "
        "more than 1 % of the "
        "energy lost by the end), **stable**. Energy drift: the largest |E/E0 - 1| over the run, "
        "signed (+ gained, - lost); penetration relative to the smaller body's size.\n\n";
  Table st({"scene", "backend", "dt (s)", "e", "verdict", "energy drift", "max penetration",
            "at rest", "tunnelled", "jitter (m/s)", "why"});
  bool any_stab = false;
  for (size_t i = 0; i < evs.size(); ++i) {
    // The verdict at the scene's step, then at the other steps of its own dt study (if it names
    // one), each backend's rows together.
    for (const StabilityRow& s : evs[i].stability) {
      any_stab = true;
      std::string why;
      for (const std::string& w : s.why) why += (why.empty() ? "" : "; ") + w;
      const double drift = s.energy_drift_rel;
      st.add({scenes[i].name, s.backend, fmt_num(s.dt, 3), fmt_num(s.restitution, 3), s.verdict,
              (drift > 0 ? "+" : "") + fmt_num(100 * drift, 3) + " %",
              fmt_num(100 * s.max_penetration_rel, 3) + " %",
              fmt_num(100 * s.rest_penetration_rel, 3) + " %", std::to_string(s.tunnelled_pairs),
              s.jitter_rms_mps ? fmt_num(*s.jitter_rms_mps, 3) : "-", why});
    }
  }
  md << (any_stab ? st.markdown() : std::string("No scene asks for the stability check.\n"))
     << "\n";

  return md.str();
}

// One section per scene: statuses, metrics, findings and its figures.
std::string scene_details_section(const std::vector<Scene>& scenes,
                                  const std::vector<SceneEvaluation>& evs, bool figures_ok,
                                  bool views_ok) {
  std::ostringstream md;
  md << "## Scenes\n\n";
  for (size_t i = 0; i < evs.size(); ++i) {
    const SceneEvaluation& ev = evs[i];
    const std::string slug = scene_slug(ev.family, scenes[i].file);
    md << "### " << md_escape(ev.family + "/" + scenes[i].name) << "\n\n";
    if (!scenes[i].description.empty()) md << md_escape(scenes[i].description) << "\n\n";
    md << md_code(scenes[i].file);
    if (views_ok) md << " — [3-D replay](" << md_url("views/" + slug + ".html") << ")";
    md << "\n\n";
    Table status({"backend", "status", "run time (s)", "message"});
    for (const BackendRun& r : ev.runs)
      status.add(
          {r.backend, to_string(r.status), fmt_num(r.runtime_s.value_or(0.0), 3), r.message});
    md << status.markdown() << "\n";
    if (!ev.metrics.empty()) {
      Table mt({"check", "pair", "metric", "backend", "value", "against"});
      for (const Metric& m : ev.metrics)
        mt.add({m.check, m.pair, m.name, m.backend, fmt_num(m.value, 4), m.against});
      md << mt.markdown() << "\n";
    }
    for (const std::string& d : ev.disagreements) md << "- disagrees: " << d << "\n";
    for (const std::string& d : ev.deviations)
      md << "- deviates (within the ✗ bounds): " << d << "\n";
    for (const std::string& s : ev.skipped) md << "- left out: " << s << "\n";
    if (scenes[i].expect)
      md << "- [expect]: "
         << (!ev.expect_failures.empty() ? "FAILED"
             : ev.expect_checked         ? "passed"
                                         : "not checked")
         << "\n";
    for (const std::string& f : ev.expect_unchecked) md << "  - not checked: " << f << "\n";
    for (const std::string& f : ev.expect_failures) md << "  - " << f << "\n";
    if (scenes[i].expect && !scenes[i].expect->known_failure.empty())
      md << "  - known failure: " << scenes[i].expect->known_failure << "\n";
    if (figures_ok) {
      if (scenes[i].has_check(CheckKind::Contact) && ev.has_geometry)
        md << "\n![contacts](" << md_url("figures/contact_" + slug + ".png") << ")\n";
      if (find_metric(ev, "custom", "velocity_err_ke") || ev.run_of("bullet"))
        if (scenes[i].has_check(CheckKind::Impulse))
          md << "\n![velocities](" << md_url("figures/velocity_" + slug + ".png") << ")\n";
    }
    md << "\n";
  }
  return md.str();
}

}  // namespace

std::vector<std::string> report_columns(const std::vector<SceneEvaluation>& evs) {
  std::vector<std::string> cols;
  for (const Backend& b : backends())
    for (const SceneEvaluation& ev : evs)
      if (ev.run_of(b.name)) {
        cols.push_back(b.name);
        break;
      }
  return cols;
}

std::string error_vs_runtime_markdown(const std::vector<SceneEvaluation>& evs,
                                      const std::string& report_dir, bool figures_ok,
                                      const std::string& figures_msg) {
  std::ostringstream md;
  md << "## Error against run time\n\n";
  md << "Dynamics: each backend is run at every time step of the scene's `dt_study` (default 4, "
        "2, 1, 1/2 and 1/4 times `dt`). One point per (backend, time step): the **median over the "
        "family's closed-form scenes** of the velocity error in the kinetic-energy norm, with the "
        "25-75 % band as a bar, against the median run time of one scene run; the large open "
        "marker is the coarsest step; the same scenes stand behind every point of a curve "
        "(self-consistency errors are in `error_vs_runtime.csv` only). Contacts: one point per "
        "backend, "
        "normal angle error and depth error in two panels, median over the scenes with the 25-75 "
        "% band on both axes and the worst scene as a small hollow marker; filled markers time "
        "the backend as it runs (the library's shape built in each query), the larger hollow "
        "marker on the same row, joined by a dotted line, the same query with its shapes "
        "prebuilt (the query-time table in details.md). Errors under 1e-13 are round-off and are "
        "drawn at "
        "1e-15 "
        "in the grey band. The dashed line is the Pareto front over backends. Numbers: "
        "`error_vs_runtime.csv`, `metrics.csv`.\n\n";
  // A family's figure is named for its kind of error-against-run-time point (plots.py): contact
  // queries (timed per call or prebuilt) "-contact"; only figures plots.py drew are linked (a
  // dynamics family with no closed form has none).
  std::set<std::string> families;
  for (const SceneEvaluation& ev : evs)
    for (const ErrorRuntimePoint& p : ev.error_vs_runtime)
      families.insert(ev.family + (p.kind.rfind("contact", 0) == 0 ? "-contact" : ""));
  if (!figures_ok) md << "_Figures were not drawn: " << figures_msg << "_\n\n";
  for (const std::string& f : families) {
    const std::string file = "figures/error_vs_runtime_" + f + ".png";
    if (figures_ok && std::filesystem::exists(std::filesystem::path(report_dir) / file))
      md << "![error against run time, " << md_escape(f) << "](" << md_url(file) << ")\n\n";
  }
  if (!budget_rows(evs).empty())
    md << "Along each solver's iteration budget (the right-hand panels): the smallest budget "
          "that reaches each backend's own converged error, per family, is in "
          "[details.md](details.md) (its section *Solver budgets*; docs/solver_budgets.md).\n\n";
  return md.str();
}

std::string solver_budgets_markdown(const std::vector<SceneEvaluation>& evs) {
  const std::vector<BudgetRow> rows = budget_rows(evs);
  if (rows.empty()) return "";
  std::ostringstream md;
  md << "## Solver budgets\n\n"
        "Each dynamics backend with an iteration budget is also run at the scene's own step "
        "along that budget (the right-hand panel of each error-against-run-time figure in "
        "report.md; `error_vs_runtime.csv`, kind `budget`), measured against the same truth as the "
        "step "
        "dt study. A backend's own "
        "converged error on a scene is its error at the largest budget; the table gives the "
        "smallest budget from which every larger one is within "
     << fmt_num(100 * kBudgetConvergedRel, 3) << " % of it (or both are round-off, under "
     << fmt_num(kBudgetRoundoff, 3)
     << "), on every scene of the family and on the median scene, and the median over the "
        "scenes of the error at the library's default budget and of the converged error.\n\n";
  std::set<std::string> named;
  for (const BudgetRow& r : rows) {
    const Backend* be = find_backend(r.backend);
    if (!be || !named.insert(r.backend).second) continue;
    std::string values;
    for (int v : be->budget.values) values += (values.empty() ? "" : ", ") + std::to_string(v);
    md << "- `" << r.backend << "`: " << be->budget.what << "; studied at " << values
       << "; library default "
       << (be->budget.library_default > 0 ? std::to_string(be->budget.library_default)
                                          : std::string("none (it solves to convergence)"))
       << "; rbx runs "
       << (be->budget.configured > 0
               ? std::to_string(be->budget.configured)
               : std::string("no iteration count (an exact or converged solve)"))
       << "\n";
  }
  md << "\n";
  Table t({"backend", "family", "scenes", "converged from (every scene)",
           "converged from (median scene)", "error at the library default (median)",
           "converged error (median)"});
  for (const BudgetRow& r : rows)
    t.add({r.backend, md_escape(r.family), std::to_string(r.scenes), std::to_string(r.every_scene),
           std::to_string(r.median_scene),
           r.default_error < 0 ? std::string("—") : fmt_num(r.default_error, 3),
           fmt_num(r.converged_error, 3)});
  md << t.markdown() << "\n";
  return md.str();
}

Json geometry_json(const Scene& scene) {
  Json g = Json::array();
  for (const RigidBody& b : make_bodies(scene)) {
    if (b.shape->vertices().size() > 2000) return Json::array();
    Json verts = Json::array();
    for (size_t i = 0; i < b.shape->vertices().size(); ++i)
      verts.push_back(to_json(b.world_vertex(static_cast<int>(i))));
    Json tris = Json::array();
    for (const auto& t : b.shape->triangles()) tris.push_back({t[0], t[1], t[2]});
    g.push_back({{"name", b.name}, {"vertices", verts}, {"triangles", tris}});
  }
  return g;
}

std::string report_details_markdown(const std::vector<Scene>& scenes,
                                    const std::vector<SceneEvaluation>& evs,
                                    const std::string& report_dir, bool figures_ok, bool views_ok,
                                    double timing_budget_s) {
  std::ostringstream md;
  const std::vector<std::string> cols = report_columns(evs);
  md << "# rbx accuracy report: every table\n\n"
        "The summary, its figures and the real tosses are in [report.md](report.md) "
        "([index.html](index.html) as a page); here, every table in full and every scene's "
        "numbers. The same numbers as CSV: [metrics.csv](metrics.csv), "
        "[error_vs_runtime.csv](error_vs_runtime.csv), "
        "[stability.csv](stability.csv), [laws.csv](laws.csv).\n\n";
  std::vector<FailureCause> causes;
  const std::vector<ScoreRow> rows = score_rows(scenes, evs, cols, &causes);
  md << scorecard_markdown(rows, timing_budget_s) << causes_markdown(causes, false, views_ok);
  md << summary_section(scenes, evs, cols, views_ok) << contact_phase_section(scenes, evs, cols)
     << disagreement_section(scenes, evs, cols);
  if (const std::string q = query_time_markdown(evs, cols, timing_budget_s); !q.empty())
    md << "## Contact query time\n\n" << q;
  md << solver_budgets_markdown(evs);
  md << stability_section(scenes, evs) << contact_laws_details_markdown(scenes, evs, cols)
     << predictability_markdown(scenes, evs, report_dir, figures_ok)
     << scene_details_section(scenes, evs, figures_ok, views_ok);
  return md.str();
}

void write_report_tables(const std::string& dir, const std::vector<Scene>& scenes,
                         const std::vector<SceneEvaluation>& evs) {
  const fs::path tmp(dir);
  Json results;
  results["generated_by"] = "rbx report";
  results["backends"] = Json::array();
  for (const Backend& b : backends())
    results["backends"].push_back({{"name", b.name},
                                   {"description", b.description},
                                   {"contact", static_cast<bool>(b.contact)},
                                   {"dynamics", static_cast<bool>(b.dynamics)}});
  results["scenes"] = Json::array();
  for (const SceneEvaluation& ev : evs) results["scenes"].push_back(results_scene_json(ev.json));
  // Compact: two-space indentation tripled the size (13.9 MB against 4.4 MB for the library).
  write_text((tmp / "results.json").string(), results.dump() + "\n");

  std::ostringstream metrics, points, stab;
  metrics << "scene,family,check,backend,pair,metric,value,against\n";
  points << "scene,family,backend,kind,dt,budget,runtime_s,error,against,runtime_q25_s,"
            "runtime_q75_s,calls,rounds,cold_s\n";
  stab << "scene,family,backend,dt,restitution,verdict,energy_growth_rel,energy_drift_rel,"
          "max_penetration_rel,rest_penetration_rel,tunnelled_pairs,jitter_rms_mps\n";
  for (size_t i = 0; i < evs.size(); ++i) {
    const std::string sc = csv_escape(scenes[i].name), fam = evs[i].family;
    for (const Metric& m : evs[i].metrics)
      metrics << sc << "," << fam << "," << m.check << "," << m.backend << "," << m.pair << ","
              << m.name << "," << fmt_num(m.value, 17) << "," << csv_escape(m.against) << "\n";
    for (const ErrorRuntimePoint& p : evs[i].error_vs_runtime)
      points << sc << "," << fam << "," << p.backend << "," << p.kind << "," << fmt_num(p.dt, 17)
             << "," << p.budget << "," << fmt_num(p.timing.median_s, 6) << ","
             << fmt_num(p.error, 17) << "," << csv_escape(p.against) << ","
             << fmt_num(p.timing.q25_s, 6) << "," << fmt_num(p.timing.q75_s, 6) << ","
             << p.timing.calls << "," << p.timing.rounds << "," << fmt_num(p.timing.cold_s, 6)
             << "\n";
    for (const StabilityRow& s : evs[i].stability)  // the scene's step, then its dt study
      stab << sc << "," << fam << "," << s.backend << "," << fmt_num(s.dt, 17) << ","
           << fmt_num(s.restitution, 17) << "," << s.verdict << ","
           << fmt_num(s.energy_growth_rel, 17) << "," << fmt_num(s.energy_drift_rel, 17) << ","
           << fmt_num(s.max_penetration_rel, 17) << "," << fmt_num(s.rest_penetration_rel, 17)
           << "," << s.tunnelled_pairs << ","
           << (s.jitter_rms_mps ? fmt_num(*s.jitter_rms_mps, 17) : "") << "\n";
  }
  write_text((tmp / "metrics.csv").string(), metrics.str());
  write_text((tmp / "error_vs_runtime.csv").string(), points.str());
  write_text((tmp / "stability.csv").string(), stab.str());
  write_text((tmp / "laws.csv").string(), laws_csv(scenes, evs, report_columns(evs)));
}

bool draw_report_figures(const std::string& dir, int jobs, std::string& message) {
  const fs::path tmp(dir);
  // Figures: matplotlib from Debian, the figures shared among `jobs` processes.
  const int rc = run_figure_script("plots.py", {tmp.string(), std::to_string(std::max(1, jobs))},
                                   (tmp / "figures.log").string(), &message);
  if (rc == 0) {
    fs::remove(tmp / "figures.log");
    return true;
  }
  if (rc > 0) message = "plots.py failed (see figures.log)";
  return false;
}

}  // namespace rbx
