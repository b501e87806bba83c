#include "comparisons/output/scorecard.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

#include "comparisons/eval/contact_cause.h"
#include "comparisons/eval/ensemble.h"
#include "comparisons/eval/law_residuals.h"
#include "comparisons/output/table.h"
#include "engine/format.h"
#include "reference/backend.h"

namespace rbx {

namespace {

// True when one of the lines is about backend `name` (lines start "NAME " or "NAME:").
bool about(const std::vector<std::string>& lines, const std::string& name) {
  for (const std::string& d : lines)
    if (d.rfind(name + " ", 0) == 0 || d.rfind(name + ":", 0) == 0) return true;
  return false;
}

// The largest value of metric `name` of a backend against a truth (closed form, exact oracle or
// exact solid), or -1 when there is none.
double truth_metric(const SceneEvaluation& ev, const std::string& backend,
                    const std::string& name) {
  double worst = -1.0;
  for (const Metric& m : ev.metrics)
    if (m.backend == backend && m.name == name &&
        (m.against == "analytic" || m.against.rfind("exact", 0) == 0))
      worst = std::max(worst, m.value);
  return worst;
}

// Why a backend failed a scene, measured: the status, then the first clear sign in the metrics.
std::string cause(const SceneEvaluation& ev, const BackendRun& run) {
  const std::string& backend = run.backend;
  if (run.status == Status::Error || run.status == Status::Timeout) {
    std::string msg = run.message;
    if (msg.size() > 120) msg = msg.substr(0, msg.rfind(' ', 117)) + " ...";
    return std::string(to_string(run.status)) + ": " + msg;
  }
  // A marked contact answer: the first sign measured on it (contact_cause.h).
  for (const Cause& c : ev.causes)
    if (c.check == "contact" && c.backend == backend &&
        c.kind != std::string(contact_sign::kTouchingAtZeroDepth))
      return c.kind;
  if (truth_metric(ev, backend, "touching_err") > 0)
    return "misses a contact or reports a false one";
  const double angle = truth_metric(ev, backend, "normal_err_deg");
  const double depth = truth_metric(ev, backend, "depth_err");
  if (angle > kMarkAngleDeg) return "wrong contact normal (> 1°)";
  if (depth > 0) {
    for (const std::string& d : ev.disagreements)
      if (d.rfind(backend + " ", 0) == 0 && d.find("depth off") != std::string::npos)
        return "wrong depth, normal within 1°";
  }
  for (const Metric& m : ev.metrics)
    if (m.backend == backend &&
        (m.name == "inertia_err_rel" || m.name == "mass_err_rel" || m.name == "com_err_rel") &&
        m.value > 1e-6)
      return "mass properties off (relative > 1e-6)";
  if (!run.stability.empty() && run.stability != "stable") return "stability: " + run.stability;
  for (const std::string& d : ev.disagreements)
    if (d.rfind(backend + ":", 0) == 0) {
      if (d.find("angular_velocity") != std::string::npos)
        return "post-impact angular velocity off (> 0.1 %, energy norm)";
      if (d.find("velocity") != std::string::npos)
        return "post-impact velocity off (> 0.1 %, energy norm)";
      if (d.find("position") != std::string::npos) return "final position off";
    }
  return "outside the scene's tolerance (within the ✗ bounds)";
}

std::string fmt_err(double x, const std::string& unit) {
  return x < 0 ? "-" : fmt_num(x, 2) + unit;
}

double max_of(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }

// What a scene measures: its checks decide, whatever errors the backends produced. A scene that
// checks a contact and the motion it leads to (scenes/resting) is scored on the motion.
Measure measure_of(const Scene& scene) {
  if (scene.has_check(CheckKind::Trajectory) || scene.has_check(CheckKind::Impulse))
    return Measure::Dynamics;
  if (scene.has_check(CheckKind::Contact)) return Measure::Contact;
  if (scene.has_check(CheckKind::Mass)) return Measure::Mass;
  return Measure::Dynamics;
}

// Adds one scene's errors and run time to a row (the backend answered: status ok, or touching
// with no normal, which adds its time and no error).
void add_scene(ScoreRow& row, const Scene& scene, const SceneEvaluation& ev,
               const BackendRun& run) {
  const std::string& b = row.backend;
  if (row.measure == Measure::Contact) {
    if (const double a = truth_metric(ev, b, "normal_err_deg"); a >= 0) {
      row.error.push_back(a);
      row.depth_error.push_back(std::max(truth_metric(ev, b, "depth_err"), 0.0));
    }
    if (const double c = truth_metric(ev, b, "coverage_err_rel"); c >= 0) row.coverage.push_back(c);
    for (const ErrorRuntimePoint& p : ev.error_vs_runtime) {
      if (p.backend == b && (p.kind == "contact" || p.kind == "contact-touching"))
        row.time.push_back(p.timing.median_s);
      if (p.backend == b && p.kind == "contact-prebuilt") row.prebuilt.push_back(p.timing.median_s);
    }
    return;
  }
  if (row.measure == Measure::Mass) {
    const double m =
        std::max({truth_metric(ev, b, "mass_err_rel"), truth_metric(ev, b, "com_err_rel"),
                  truth_metric(ev, b, "inertia_err_rel")});
    if (m >= 0) row.error.push_back(m);
    return;
  }
  if (const double v = truth_metric(ev, b, "velocity_err_ke"); v >= 0) row.error.push_back(v);
  if (const SceneLaws laws = scene_laws(scene, ev, b); laws.measured && laws.contacts > 0) {
    const auto [law, relative] = worst_relative(laws);
    if (relative > row.law_relative) {
      row.law_relative = relative;
      row.law = to_string(law);
    }
  }
  // The ensemble's amplification, where the scene has one and the backend's copies ran.
  if (ev.ensemble)
    for (const BackendEnsemble& e : ev.ensemble->backends)
      if (e.backend == b && e.runs > 0) row.amplification.push_back(e.amplification);
  const long steps = scene.sim.steps();
  if (steps > 0 && run.runtime_s) row.time.push_back(*run.runtime_s / static_cast<double>(steps));
}

// Errors below this rank as equal: round-off and the iterative methods' stopping tolerances
// (1e-10 in the adapters) are not a difference in accuracy, and 3e-13 deg is not worse than 0.
constexpr double kRankNoise = 1e-9;

// A value as the tables show it (2 significant digits), noise as 0: rows that read the same
// rank by the next criterion.
double as_shown(double x) {
  if (x < kRankNoise) return 0.0;
  const double scale = std::pow(10.0, std::floor(std::log10(x)) - 1);
  return std::round(x / scale) * scale;
}

// Ranking within a group: rows with an error first, by median error as shown (contact: angle,
// then depth), then most scenes within tolerance, then worst error, then run time.
bool ranks_before(const ScoreRow& a, const ScoreRow& b) {
  auto key = [](const ScoreRow& r) {
    const double none = std::numeric_limits<double>::infinity();
    auto rank_value = [&](const std::vector<double>& v, bool worst) {
      if (v.empty()) return none;
      const double x = worst ? max_of(v) : median_of(v);
      return as_shown(x);
    };
    return std::make_tuple(r.error.empty(), rank_value(r.error, false),
                           rank_value(r.depth_error, false), -r.within, rank_value(r.error, true),
                           rank_value(r.depth_error, true),
                           r.time.empty() ? none : median_of(r.time));
  };
  return key(a) < key(b);
}

const char* measure_title(Measure m) {
  switch (m) {
    case Measure::Contact:
      return "contacts: normal angle (deg) / depth error (m) against the truth, time per query";
    case Measure::Mass:
      return "mass properties: worst relative error of mass, centre of mass and inertia";
    case Measure::Dynamics:
      break;
  }
  return "dynamics: post-impact velocity error, relative (kinetic-energy norm; 0.001 is 0.1 %), "
         "time per step";
}

}  // namespace

std::string ScoreRow::within_text() const {
  return std::to_string(within) +
         (within == run ? "" : " (" + std::to_string(run - within) + " not)") +
         (touching ? ", " + std::to_string(touching) + " touching with no normal" : "");
}

std::string ScoreRow::median_text() const {
  if (error.empty()) return "-";
  const std::string n = " (" + std::to_string(error.size()) + ")";
  if (measure == Measure::Contact)
    return fmt_err(median_of(error), "°") + " / " + fmt_err(median_of(depth_error), "") + n;
  return fmt_err(median_of(error), "") + n;
}

std::string ScoreRow::worst_text() const {
  if (error.empty()) return "-";
  if (measure == Measure::Contact)
    return fmt_err(max_of(error), "°") + " / " + fmt_err(max_of(depth_error), "");
  return fmt_err(max_of(error), "");
}

std::string ScoreRow::time_text() const {
  if (time.empty()) return "-";
  std::string t =
      fmt_num(median_of(time) * 1e6, 3) + (measure == Measure::Contact ? " µs/query" : " µs/step");
  // The library's query with its shapes built once, where it has that variant.
  if (!prebuilt.empty()) t += " (" + fmt_num(median_of(prebuilt) * 1e6, 3) + " prebuilt)";
  return t;
}

std::string ScoreRow::predictability_text() const {
  if (amplification.empty()) return "—";
  return fmt_num(median_of(amplification), 2) + " (" + std::to_string(amplification.size()) + ")";
}

std::string ScoreRow::coverage_text() const {
  if (coverage.empty()) return "—";
  return fmt_err(median_of(coverage), "") + " / " + fmt_err(max_of(coverage), "") + " (" +
         std::to_string(coverage.size()) + ")";
}

std::string ScoreRow::law_text() const {
  if (law_relative < 0) return "—";
  return fmt_num(law_relative, 2) + " (" + law + ")";
}

std::string group_title(const ScoreRow& row) {
  return row.family + " — " + measure_title(row.measure);
}

std::string scene_slug(const std::string& family, const std::string& file) {
  return family + "_" + std::filesystem::path(file).stem().string();
}

std::string md_escape(const std::string& text) {
  // Leading spaces and tabs would indent a line into a code block or a nested list; they say
  // nothing in a name or a description, so they are dropped.
  const std::string s = text.substr(std::min(text.find_first_not_of(" \t"), text.size()));
  // A list marker opens a list only at the start of a line: escaping it there (a digit run's
  // '.' or ')', a leading '-' or '+') keeps the text a paragraph wherever it is placed.
  size_t digits = 0;
  while (digits < s.size() && std::isdigit(static_cast<unsigned char>(s[digits]))) ++digits;
  const size_t marker = digits;
  const bool list = marker < s.size() && (digits > 0 ? s[marker] == '.' || s[marker] == ')'
                                                     : s[marker] == '-' || s[marker] == '+');
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    char c = s[i];
    // '&' would start an entity (md4c decodes "&lt;"), '~' a strikethrough in GitHub's Markdown.
    if (std::string("\\`*_[]<>|#&~").find(c) != std::string::npos || (list && i == marker))
      out += '\\';
    if (c == '\n' || c == '\r') c = ' ';
    out += c;
  }
  return out;
}

std::string md_url(const std::string& path) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (const unsigned char c : path) {
    if (std::isalnum(c) || std::string("-._~/").find(static_cast<char>(c)) != std::string::npos) {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

std::string md_code(const std::string& text) {
  std::string s = text;
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  size_t longest = 0, run = 0;
  for (const char c : s) {
    run = c == '`' ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  const std::string fence(longest + 1, '`');
  // CommonMark strips one space from each end of a code span that starts and ends with one.
  const bool pad =
      !s.empty() && (s.front() == '`' || s.back() == '`' || (s.front() == ' ' && s.back() == ' '));
  return fence + (pad ? " " : "") + s + (pad ? " " : "") + fence;
}

std::vector<ScoreRow> score_rows(const std::vector<Scene>& scenes,
                                 const std::vector<SceneEvaluation>& evs,
                                 const std::vector<std::string>& backends,
                                 std::vector<FailureCause>* causes) {
  // Groups (family, measure) in the order the scenes come.
  std::vector<std::pair<std::string, Measure>> groups;
  for (size_t i = 0; i < evs.size(); ++i) {
    const std::pair<std::string, Measure> g{evs[i].family, measure_of(scenes[i])};
    if (std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
  }
  std::vector<ScoreRow> rows;
  std::vector<FailureCause> found;
  for (const auto& [fam, measure] : groups) {
    std::vector<ScoreRow> group;
    for (const std::string& b : backends) {
      ScoreRow row;
      row.backend = b;
      row.family = fam;
      row.measure = measure;
      for (size_t i = 0; i < evs.size(); ++i) {
        const SceneEvaluation& ev = evs[i];
        const BackendRun* run = ev.run_of(b);
        if (ev.family != fam || measure_of(scenes[i]) != measure || !run) continue;
        if (run->status == Status::Unsupported) continue;
        ++row.run;
        const bool bad = run->status == Status::Error || run->status == Status::Timeout ||
                         about(ev.disagreements, b) || about(ev.deviations, b);
        if (bad) {
          const std::string c = cause(ev, *run);
          auto it = std::find_if(found.begin(), found.end(), [&](const FailureCause& f) {
            return f.backend == b && f.cause == c;
          });
          if (it == found.end()) it = found.insert(found.end(), {b, c, {}});
          it->scenes.push_back({fam + "/" + scenes[i].name, scene_slug(fam, scenes[i].file)});
        } else {
          ++row.within;
        }
        if (run->status == Status::Touching) ++row.touching;
        // A touching answer has no normal to score, but its query time counts like any.
        if (run->status == Status::Ok || run->status == Status::Touching)
          add_scene(row, scenes[i], ev, *run);
      }
      if (row.run > 0) group.push_back(std::move(row));
    }
    std::stable_sort(group.begin(), group.end(), ranks_before);
    for (ScoreRow& r : group) rows.push_back(std::move(r));
  }
  // Causes in backend order, each backend's in the order first met.
  if (causes) {
    causes->clear();
    for (const std::string& b : backends)
      for (const FailureCause& f : found)
        if (f.backend == b) causes->push_back(f);
  }
  return rows;
}

std::string scorecard_markdown(const std::vector<ScoreRow>& rows, double timing_budget_s) {
  std::ostringstream md;
  md << "## Scorecard\n\n"
        "One table per scene family, backends ranked by their median error against the truth "
        "(the closed form, the `exact` oracle or the exact solid; self-consistency errors are "
        "not counted) as shown, errors under 1e-9 (round-off, iteration tolerances) counting "
        "as equal; then by scenes within tolerance, worst error and run time. *Within "
        "tolerance*: scenes with no ✗ and no ~ in the full tables (details.md); `unsupported` "
        "scenes are not counted. *Median error (n)*: the median over the n scenes that have a "
        "truth to compare with (the others have none). Run time: median over the scenes of "
     << (timing_budget_s > 0
             ? "each scene's warm median (a dynamics run repeated, a query repeated; "
               "docs/bench.md), "
             : "each scene's one call (this run timed no repeats: `--timing-budget 0`), ")
     << "wall clock; a library builds its shapes inside each query, custom reuses its hulls; "
        "in brackets the same query with the library's shapes prebuilt, the fair comparison "
        "with custom. *Coverage error* (contacts): how far the backend's points fall short of the "
        "true contact patch, the largest distance from a corner of the `exact` patch to the hull "
        "of the points across the normal, relative to the smaller body (0: the points span the "
        "patch), median and worst over the n scenes with a patch (docs/contact_manifold.md). "
        "*Worst contact-law residual* (dynamics): the largest residual of the "
        "contact laws over the family's scenes, relative to its scene's scale, and its law "
        "(the \"Contact laws\" section). *Predictability* (families with ensembles): the "
        "median over the family's ensembles of how many times the nudge the final positions "
        "spread, with their number (the \"Predictability\" section).\n\n";
  for (size_t k = 0; k < rows.size();) {
    size_t end = k;
    while (end < rows.size() && rows[end].family == rows[k].family &&
           rows[end].measure == rows[k].measure)
      ++end;
    md << "### " << md_escape(group_title(rows[k])) << "\n\n";
    // Dynamics groups also show the worst contact-law residual (report.md, "Contact laws").
    const bool laws = rows[k].measure == Measure::Dynamics;
    // And, where the family has ensembles, the predictability (report.md, "Predictability").
    bool ensembles = false;
    for (size_t r = k; r < end; ++r) ensembles = ensembles || !rows[r].amplification.empty();
    std::vector<std::string> header = {
        "rank",         "backend",     "scenes run",     "within tolerance",
        "median error", "worst error", "median run time"};
    // Contact groups: how much of the true patch the points span (patch_cover.h).
    const bool cover = rows[k].measure == Measure::Contact;
    if (cover) header.push_back("coverage error, median / worst (n)");
    if (laws) header.push_back("worst contact-law residual");
    if (ensembles) header.push_back("predictability (median amplification)");
    Table t(header);
    for (size_t r = k; r < end; ++r) {
      std::vector<std::string> cells = {
          std::to_string(r - k + 1),   "**" + md_escape(rows[r].backend) + "**",
          std::to_string(rows[r].run), rows[r].within_text(),
          rows[r].median_text(),       rows[r].worst_text(),
          rows[r].time_text()};
      if (cover) cells.push_back(rows[r].coverage_text());
      if (laws) cells.push_back(rows[r].law_text());
      if (ensembles) cells.push_back(rows[r].predictability_text());
      t.add(cells);
    }
    md << t.markdown() << "\n";
    k = end;
  }
  return md.str();
}

std::string scorecard_matrix_markdown(const std::vector<ScoreRow>& rows) {
  // Groups in scorecard order; in each, a backend's rank is its row's place.
  std::vector<std::pair<size_t, size_t>> groups;  // [begin, end) of each group's rows
  for (size_t k = 0; k < rows.size();) {
    size_t end = k;
    while (end < rows.size() && rows[end].family == rows[k].family &&
           rows[end].measure == rows[k].measure)
      ++end;
    groups.emplace_back(k, end);
    k = end;
  }
  // Backends in the registry's order (those registered at run time after, by name).
  std::vector<std::string> names;
  for (const ScoreRow& r : rows)
    if (std::find(names.begin(), names.end(), r.backend) == names.end()) names.push_back(r.backend);
  auto registry_index = [](const std::string& name) {
    const std::vector<Backend>& table = backends();
    for (size_t i = 0; i < table.size(); ++i)
      if (table[i].name == name) return i;
    return table.size();
  };
  std::stable_sort(names.begin(), names.end(), [&](const std::string& a, const std::string& b) {
    return std::make_tuple(registry_index(a), a) < std::make_tuple(registry_index(b), b);
  });
  std::vector<std::string> header = {"backend"};
  for (const auto& [begin, end] : groups)
    header.push_back(md_escape(rows[begin].family) + " (" +
                     (rows[begin].measure == Measure::Contact ? "contacts"
                      : rows[begin].measure == Measure::Mass  ? "mass"
                                                              : "dynamics") +
                     ")");
  Table t(header);
  for (const std::string& name : names) {
    std::vector<std::string> cells = {"**" + md_escape(name) + "**"};
    for (const auto& [begin, end] : groups) {
      std::string cell = "";
      for (size_t r = begin; r < end; ++r) {
        if (rows[r].backend != name) continue;
        const ScoreRow& row = rows[r];
        std::string median = "-";
        if (!row.error.empty())
          median = row.measure == Measure::Contact ? fmt_err(median_of(row.error), "°") + " / " +
                                                         fmt_err(median_of(row.depth_error), "")
                                                   : fmt_err(median_of(row.error), "");
        cell = "#" + std::to_string(r - begin + 1) + " " + median + ", " +
               std::to_string(row.within) + "/" + std::to_string(row.run);
      }
      cells.push_back(cell.empty() ? "·" : cell);
    }
    t.add(cells);
  }
  std::ostringstream md;
  md << "## Scorecard\n\n"
        "Each cell: the backend's rank in its family (by median error against the truth, then "
        "scenes within tolerance, worst error and run time), its median error (contacts: normal "
        "angle / depth in m; dynamics: post-impact velocity error, kinetic-energy norm; mass: "
        "relative error) and its scenes within tolerance of those it ran; · where it ran none. "
        "Each family's ranked table, with the worst error, the run time (and with the library's "
        "shapes prebuilt), the worst contact-law residual and the predictability, is in "
        "[details.md](details.md) (its section *Scorecard*).\n\n"
     << t.markdown() << "\n";
  return md.str();
}

std::string causes_markdown(const std::vector<FailureCause>& causes, bool compact, bool views) {
  std::ostringstream md;
  md << "### Causes of the failures, measured\n\n";
  if (causes.empty()) md << "Every backend is within tolerance on every scene it ran.\n";
  auto link = [&](const SceneRef& s) {
    const std::string name = md_escape(s.name);
    return views ? "[" + name + "](" + md_url("views/" + s.slug + ".html") + ")" : name;
  };
  for (size_t k = 0; k < causes.size(); ++k) {
    const FailureCause& f = causes[k];
    if (compact) {
      // One line per backend: each cause, its count and one scene; details.md names them all.
      if (k > 0 && causes[k - 1].backend == f.backend) continue;
      md << "- **" << md_escape(f.backend) << "**: ";
      for (size_t j = k; j < causes.size() && causes[j].backend == f.backend; ++j)
        md << (j > k ? "; " : "") << md_escape(causes[j].cause) << ", " << causes[j].scenes.size()
           << " (e.g. " << link(causes[j].scenes.front()) << ")";
      md << "\n";
      continue;
    }
    md << "- **" << md_escape(f.backend) << "**: " << md_escape(f.cause) << " — " << f.scenes.size()
       << ": ";
    for (size_t j = 0; j < f.scenes.size(); ++j) md << (j ? ", " : "") << link(f.scenes[j]);
    md << "\n";
  }
  md << "\n";
  return md.str();
}

std::string query_time_markdown(const std::vector<SceneEvaluation>& evs,
                                const std::vector<std::string>& backends, double timing_budget_s) {
  // Pairs (per call, prebuilt) of one query, per backend: the harness writes a query's
  // prebuilt point right after its per-call point (none when the answers differed).
  std::map<std::string, std::vector<Timing>> per_call;
  std::map<std::string, std::vector<double>> prebuilt, built;
  for (const SceneEvaluation& ev : evs)
    for (size_t k = 0; k < ev.error_vs_runtime.size(); ++k) {
      const ErrorRuntimePoint& p = ev.error_vs_runtime[k];
      if ((p.kind == "contact" || p.kind == "contact-touching") && p.timing.rounds > 0)
        per_call[p.backend].push_back(p.timing);
      if (p.kind != "contact-prebuilt" || k == 0 || p.timing.rounds == 0) continue;
      const ErrorRuntimePoint& call = ev.error_vs_runtime[k - 1];
      if (call.kind != "contact" || call.backend != p.backend || call.timing.rounds == 0) continue;
      prebuilt[p.backend].push_back(p.timing.median_s);
      built[p.backend].push_back(call.timing.median_s - p.timing.median_s);
    }
  if (per_call.empty()) return "";
  Table t({"backend", "queries", "per call (µs)", "25-75 % over rounds", "calls timed",
           "cold call (µs)", "shapes prebuilt (µs)", "building the shapes (µs)",
           "per call / prebuilt"});
  for (const std::string& b : backends) {
    if (!per_call.count(b)) continue;
    std::vector<double> median, spread, cold;
    long calls = 0;
    for (const Timing& x : per_call[b]) {
      median.push_back(x.median_s);
      spread.push_back(x.spread());
      cold.push_back(x.cold_s);
      calls += x.calls;
    }
    const double call = median_of(median) * 1e6;
    std::vector<std::string> row = {b,
                                    std::to_string(median.size()),
                                    fmt_num(call, 3),
                                    "±" + fmt_num(50.0 * median_of(spread), 2) + " %",
                                    std::to_string(calls),
                                    fmt_num(median_of(cold) * 1e6, 3)};
    if (prebuilt[b].empty()) {
      row.insert(row.end(), {"—", "—", "—"});
    } else {
      const double pre = median_of(prebuilt[b]) * 1e6;
      row.insert(row.end(), {fmt_num(pre, 3), fmt_num(median_of(built[b]) * 1e6, 3),
                             fmt_num(call / pre, 3) + "x"});
    }
    t.add(row);
  }
  std::ostringstream md;
  md << "Contact query time, median over the queries of the run. ";
  if (timing_budget_s > 0) {
    md << "Each query is timed as benchmarks time (docs/bench.md): the backend's first call, "
          "which gave its answer, is the *cold call*, reported apart; then, after a warm-up "
          "call, rounds of repeated calls (each round long enough for the clock) until at least "
       << fmt_num(timing_budget_s * 1e3) << " ms and " << TimingPlan{}.min_rounds
       << " rounds, the backends of one pair taking turns round by round so that a passing load "
          "of the machine falls on all alike. *Per call* is the median over the rounds; *25-75 % "
          "over rounds* is half the range between a query's quartiles relative to its median "
          "(the median over the queries): how far one query's time moved while it was timed. ";
  } else {
    md << "This run timed no repeats (`--timing-budget 0`): each query was called once, so "
          "*per call* is that one cold call, with no spread over rounds. ";
  }
  md << "*Calls timed* adds up every query's. *Per call* is the backend as it runs (the library's "
        "shapes built in each query; custom, exact and libccd query our hulls directly, nothing "
        "to build). *Shapes prebuilt* is the same query with the library's shapes built once and "
        "kept, as a user holding them across steps would (the backend's \"prebuilt\" variant; "
        "its answers are checked to be bit-identical, else the run reports a disagreement); "
        "*building the shapes* is the median of the difference per query. In the figures above, "
        "hollow markers joined by a dotted line to the filled ones are the prebuilt times.\n\n"
     << t.markdown() << "\n";
  return md.str();
}

}  // namespace rbx
