#include "comparisons/output/scorecard.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>

#include "comparisons/output/table.h"
#include "engine/format.h"

namespace rbx {

namespace {

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

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
std::string cause(const SceneEvaluation& ev, const std::string& backend) {
  const Json& bj = ev.json["backends"][backend];
  if (bj["status"] == "error" || bj["status"] == "timeout") {
    std::string msg = bj["message"].get<std::string>();
    if (msg.size() > 70) msg = msg.substr(0, 67) + "...";
    return bj["status"].get<std::string>() + ": " + msg;
  }
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
  if (ev.json["stability"].contains(backend)) {
    const std::string v = ev.json["stability"][backend]["verdict"];
    if (v != "stable") return "stability: " + v;
  }
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

}  // namespace

std::string scene_slug(const std::string& family, const std::string& file) {
  return family + "_" + std::filesystem::path(file).stem().string();
}

std::string md_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (std::string("\\`*_[]<>|#").find(c) != std::string::npos) out += '\\';
    if (c == '\n' || c == '\r') c = ' ';
    out += c;
  }
  return out;
}

std::string scorecard_markdown(const std::vector<Scene>& scenes,
                               const std::vector<SceneEvaluation>& evs,
                               const std::vector<std::string>& backends, bool views) {
  std::vector<std::string> families;
  for (const SceneEvaluation& ev : evs)
    if (std::find(families.begin(), families.end(), ev.family) == families.end())
      families.push_back(ev.family);
  std::ostringstream md;
  md << "## Scorecard\n\n"
        "Per backend and scene family: scenes run (`unsupported` not counted), "
        "how many are within tolerance (no ✗ and no ~ in the full table), the error against the "
        "truth (the closed form, the `exact` oracle or the exact solid; self-consistency errors "
        "are not counted), median and worst over the scenes that have one, and the median run "
        "time per contact query or per time step (wall clock; the library builds its shapes "
        "inside each query, the custom engine reuses its hulls; in brackets, the same query "
        "with the library's shapes prebuilt, the fair comparison with custom). Contacts: normal "
        "angle / depth "
        "error (m). Dynamics: post-impact velocity error in the kinetic-energy norm. Mass: worst "
        "relative error of mass, centre of mass and inertia.\n\n";
  Table t({"backend", "family", "scenes run", "within tolerance", "median error", "worst error",
           "median run time"});
  // cause -> scene links, per backend, in the order causes were first met.
  std::map<std::string, std::vector<std::pair<std::string, std::vector<std::string>>>> causes;
  for (const std::string& b : backends) {
    for (const std::string& fam : families) {
      int run = 0, within = 0, touching = 0;  // touching: answered with no normal
      std::vector<double> e1, e2, times, prebuilt;
      bool contact = false;
      for (size_t i = 0; i < evs.size(); ++i) {
        const SceneEvaluation& ev = evs[i];
        if (ev.family != fam || !ev.json["backends"].contains(b)) continue;
        const Json& bj = ev.json["backends"][b];
        if (bj["status"] == "unsupported") continue;
        ++run;
        const bool bad = bj["status"] == "error" || bj["status"] == "timeout" ||
                         about(ev.disagreements, b) || about(ev.deviations, b);
        if (!bad)
          ++within;
        else {
          const std::string c = cause(ev, b);
          auto& list = causes[b];
          auto it =
              std::find_if(list.begin(), list.end(), [&](const auto& p) { return p.first == c; });
          if (it == list.end()) it = list.insert(list.end(), {c, {}});
          const std::string name = md_escape(fam + "/" + scenes[i].name);
          it->second.push_back(
              views ? "[" + name + "](views/" + scene_slug(fam, scenes[i].file) + ".html)" : name);
        }
        if (bj["status"] == "touching") ++touching;
        if (bj["status"] != "ok") continue;
        if (const double a = truth_metric(ev, b, "normal_err_deg"); a >= 0) {
          contact = true;
          e1.push_back(a);
          e2.push_back(std::max(truth_metric(ev, b, "depth_err"), 0.0));
          for (const SweepPoint& p : ev.sweep) {
            if (p.backend == b && p.kind == "contact") times.push_back(p.runtime_s);
            if (p.backend == b && p.kind == "contact-prebuilt") prebuilt.push_back(p.runtime_s);
          }
        } else if (const double v = truth_metric(ev, b, "velocity_err_ke"); v >= 0) {
          e1.push_back(v);
        } else if (const double m = std::max({truth_metric(ev, b, "mass_err_rel"),
                                              truth_metric(ev, b, "com_err_rel"),
                                              truth_metric(ev, b, "inertia_err_rel")});
                   m >= 0) {
          e1.push_back(m);
        }
        const long steps = scenes[i].sim.steps();
        if (!scenes[i].has_check(CheckKind::Contact) && steps > 0 && bj.contains("runtime_s") &&
            !scenes[i].has_check(CheckKind::Mass))
          times.push_back(bj["runtime_s"].get<double>() / static_cast<double>(steps));
      }
      if (run == 0) continue;
      std::string med = "-", worst = "-";
      if (!e1.empty()) {
        if (contact) {
          med = fmt_err(median_of(e1), "°") + " / " + fmt_err(median_of(e2), "");
          worst = fmt_err(*std::max_element(e1.begin(), e1.end()), "°") + " / " +
                  fmt_err(*std::max_element(e2.begin(), e2.end()), "");
        } else {
          med = fmt_err(median_of(e1), "");
          worst = fmt_err(*std::max_element(e1.begin(), e1.end()), "");
        }
        med += " (" + std::to_string(e1.size()) + ")";
      }
      std::string time = "-";
      if (!times.empty())
        time = fmt_num(median_of(times) * 1e6, 3) + (contact ? " µs/query" : " µs/step");
      // The library's query with its shapes built once, where it has that variant.
      if (!prebuilt.empty()) time += " (" + fmt_num(median_of(prebuilt) * 1e6, 3) + " prebuilt)";
      t.add({"**" + b + "**", fam, std::to_string(run),
             std::to_string(within) +
                 (within == run ? "" : " (" + std::to_string(run - within) + " not)") +
                 (touching ? ", " + std::to_string(touching) + " touching with no normal" : ""),
             med, worst, time});
    }
  }
  md << t.markdown() << "\n(n): scenes with an error against the truth.\n\n";
  md << "### Causes of the failures, measured\n\n";
  if (causes.empty()) md << "Every backend is within tolerance on every scene it ran.\n";
  for (const std::string& b : backends) {
    if (!causes.count(b)) continue;
    for (const auto& [c, list] : causes[b]) {
      md << "- **" << b << "**: " << md_escape(c) << " — " << list.size() << ": ";
      for (size_t k = 0; k < list.size(); ++k) md << (k ? ", " : "") << list[k];
      md << "\n";
    }
  }
  md << "\n";
  return md.str();
}

std::string query_time_markdown(const std::vector<SceneEvaluation>& evs,
                                const std::vector<std::string>& backends) {
  // Pairs (per call, prebuilt) of one query, per backend: the harness writes a query's
  // prebuilt point right after its per-call point (none when the answers differed).
  std::map<std::string, std::vector<double>> per_call, prebuilt, built;
  for (const SceneEvaluation& ev : evs)
    for (size_t k = 0; k < ev.sweep.size(); ++k) {
      const SweepPoint& p = ev.sweep[k];
      if (p.kind == "contact") per_call[p.backend].push_back(p.runtime_s);
      if (p.kind != "contact-prebuilt" || k == 0) continue;
      const SweepPoint& call = ev.sweep[k - 1];
      if (call.kind != "contact" || call.backend != p.backend) continue;
      prebuilt[p.backend].push_back(p.runtime_s);
      built[p.backend].push_back(call.runtime_s - p.runtime_s);
    }
  if (per_call.empty()) return "";
  Table t({"backend", "queries", "per call (µs)", "shapes prebuilt (µs)",
           "building the shapes (µs)", "per call / prebuilt"});
  for (const std::string& b : backends) {
    if (!per_call.count(b)) continue;
    const double call = median_of(per_call[b]) * 1e6;
    if (prebuilt[b].empty()) {
      t.add({b, std::to_string(per_call[b].size()), fmt_num(call, 3), "—", "—", "—"});
      continue;
    }
    const double pre = median_of(prebuilt[b]) * 1e6;
    t.add({b, std::to_string(per_call[b].size()), fmt_num(call, 3), fmt_num(pre, 3),
           fmt_num(median_of(built[b]) * 1e6, 3), fmt_num(call / pre, 3) + "x"});
  }
  std::ostringstream md;
  md << "Contact query time, median over the queries of the run. *Per call* is the backend as it "
        "runs (the library's shapes built in each query; custom, exact and libccd query our "
        "hulls directly, nothing to build). *Shapes prebuilt* is the same query with the "
        "library's shapes built once and kept, as a user holding them across steps would "
        "(the backend's \"prebuilt\" variant; its answers are checked to be bit-identical, "
        "else the run reports a disagreement); *building the shapes* is the median of the "
        "difference per query. In the figures above, hollow markers joined by a dotted line to "
        "the filled ones are the prebuilt times.\n\n"
     << t.markdown() << "\n";
  return md.str();
}

}  // namespace rbx
