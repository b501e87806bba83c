// `rbx explore`: random contact samples against the exact oracle, over every core or MPI rank;
// disagreements grouped, shrunk and written as scenes; explore.json, explore.md and a figure.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/explore.h"
#include "comparisons/eval/parallel.h"
#include "comparisons/eval/select_backends.h"
#include "comparisons/output/table.h"
#include "comparisons/scene/scene_file.h"
#include "engine/bounding.h"
#include "reference/exact.h"

namespace fs = std::filesystem;

namespace rbx {

namespace {

const char* const kMetrics[] = {"normal_err_deg",  "depth_err_rel",   "point_err_rel",
                                "velocity_err_ke", "momentum_err_ke", "position_err_m",
                                "turn_rad",        "rest_time_err_s"};

// The metrics of one kind of sample.
std::vector<std::string> metrics_of(const std::string& kind) {
  if (kind == "impact") return {"velocity_err_ke", "momentum_err_ke"};
  if (kind == "landing")
    return {"position_err_m", "turn_rad", "velocity_err_ke", "rest_time_err_s"};
  return {"normal_err_deg", "depth_err_rel", "point_err_rel"};
}

// One metric of a backend's outcome, by its name in explore.json.
double metric_value(const BackendOutcome& b, const std::string& m) {
  if (m == "normal_err_deg") return b.normal_err_deg;
  if (m == "depth_err_rel") return b.depth_err_rel;
  if (m == "point_err_rel") return b.point_err_rel;
  if (m == "velocity_err_ke") return b.velocity_err_ke;
  if (m == "momentum_err_ke") return b.momentum_err_ke;
  if (m == "position_err_m") return b.position_err_m;
  if (m == "turn_rad") return b.turn_rad;
  return b.rest_time_err_s;
}

// Nearest-rank percentile of sorted values (p in [0, 100]).
double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0.0;
  const size_t k = static_cast<size_t>(std::ceil(p / 100.0 * sorted.size()));
  return sorted[std::min(sorted.size() - 1, k == 0 ? 0 : k - 1)];
}

// Per backend: what was counted over all samples.
struct BackendTally {
  long samples = 0;
  long disagreements = 0;
  std::map<std::string, long> by_signature;
  std::map<std::string, uint64_t> first_index;  // lowest sample index of each signature
  std::map<std::string, BackendOutcome> first_outcome;
  std::map<std::string, std::vector<double>> values;  // metric -> measured values
  // Impact, landing: samples and disagreements by the quarter of its step the contact falls in.
  long phase_samples[4] = {0, 0, 0, 0}, phase_disagreements[4] = {0, 0, 0, 0};
};

std::vector<std::string> subject_backends(const std::string& list, const std::string& kind) {
  std::vector<std::string> names;
  if (list.empty() || list == "all") {
    // Every backend with a contact query (contact kind) or a dynamics run (impact, landing);
    // `exact` is the truth, not a subject.
    for (const Backend& b : backends())
      if ((kind != "contact" ? static_cast<bool>(b.dynamics) : static_cast<bool>(b.contact)) &&
          b.name != "exact")
        names.push_back(b.name);
    return names;
  }
  names = parse_backend_list(list);
  if (names.empty()) throw InputError("rbx explore: --backends: no backend named");
  return names;
}

std::string file_stem(const std::string& sig) {
  std::string s = sig;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-') c = '_';
  return s;
}

// The [expect] block of a shrunk scene: the exact oracle's answer at the t = 0 poses.
std::string expect_block(const std::string& text) {
  const Scene scene = parse_scene(text, "explore.toml");
  const std::vector<RigidBody> bodies = make_bodies(scene);
  const SatResult sat =
      sat_query(*bodies[0].shape, bodies[0].pose(), *bodies[1].shape, bodies[1].pose());
  const double size =
      std::min(2.0 * bounding_sphere(bodies[0]).radius, 2.0 * bounding_sphere(bodies[1]).radius);
  char buf[512];
  std::ostringstream o;
  o << "# Truth: the exact oracle (separating axes over faces and edge pairs), not a closed form.\n"
       "# Tolerance: 1e-6 of the smaller body (round-off of exact methods is ~1e-15 relative;\n"
       "# the disagreements explore looks for are above 1 degree or 1 % of that size).\n";
  o << "[expect]\n";
  std::snprintf(buf, sizeof buf, "tolerance = %.3g\n", std::max(1e-12, 1e-6 * size));
  o << buf << "[expect.contact]\n"
    << "touching = " << (sat.touching ? "true" : "false") << "\n";
  if (sat.touching) {
    std::snprintf(buf, sizeof buf, "normal = [%.17g, %.17g, %.17g]\ndepth = %.17g\n",
                  sat.normal.x(), sat.normal.y(), sat.normal.z(), std::max(sat.depth, 0.0));
    o << buf;
  }
  return o.str();
}

std::string describe(const BackendOutcome& b) {
  std::ostringstream o;
  if (b.error == "error" || b.error == "timeout") {
    // One line: the message goes into a scene file's comment.
    std::string m = b.message;
    std::replace(m.begin(), m.end(), '\n', ' ');
    std::replace(m.begin(), m.end(), '\r', ' ');
    return "status " + b.error + ": " + m;
  }
  if (b.error == "misses") return "misses a contact";
  if (b.error == "false_contact") return "reports a contact where there is none";
  if (b.error == "missed") return "the body flew on untouched (no impulse)";
  if (b.error == "impulse" || b.error == "spin")
    return "velocity error " + fmt_num(b.velocity_err_ke, 3) + ", momentum error " +
           fmt_num(b.momentum_err_ke, 3) + " (energy norm; " +
           (b.error == "impulse" ? "the impulse is wrong"
                                 : "the impulse is right, the spin after it is not") +
           ")";
  if (b.error == "position" || b.error == "turn")
    return "rests " + fmt_num(b.position_err_m, 3) + " m from the closed form, turned by " +
           fmt_num(b.turn_rad, 3) + " rad";
  o << "normal off by " << fmt_num(b.normal_err_deg, 3) << " deg, depth off by "
    << fmt_num(b.depth_err_rel, 3) << " and point off by " << fmt_num(b.point_err_rel, 3)
    << " of the smaller body";
  return o.str();
}

// One group's shrink, run on any rank: returns the scene and what was checked, as JSON text.
std::string shrink_group(const Json& g, uint64_t seed, long count, int budget) {
  const ContactSample start = make_contact_sample(seed, g["first_sample"].get<uint64_t>());
  const std::string backend = g["backend"], sig = g["signature"];
  const ShrinkResult r = shrink(start, backend, sig, budget);
  BackendOutcome found;
  for (const BackendOutcome& b : r.outcome.backends)
    if (b.backend == backend) found = b;
  const bool kept = !found.error.empty();
  if (!kept) {
    // The scene text of the start itself did not show the signature (should not happen: the
    // text is built as the sample is); report it instead of writing a scene that shows nothing.
    return Json{{"ok", false}}.dump();
  }
  std::ostringstream h;
  h << "# Found by `rbx explore --seed " << seed << " --count " << count << "`: sample "
    << start.index << " (" << start.pose_class << " pose), group '" << sig << "',\n# "
    << g["count"].get<long>() << " samples. " << backend
    << " against the exact oracle: " << describe(found) << ".\n# Shrunk from " << r.vertices_before
    << " to " << r.vertices_after << " points (" << r.steps_accepted << " simplifications kept, "
    << r.evaluations
    << " tried), while the disagreement stayed.\n# Reproduce: rbx compare THIS_FILE --backends "
    << backend << "\n";
  const std::string body = sample_scene_text(r.sample, h.str());
  const std::string text = body + "\n" + expect_block(body);
  std::string detail;
  bool reproduced = false;
  reproduced = harness_reproduces(text, "explore.toml", found, &detail);
  return Json{{"ok", true},
              {"text", text},
              {"points_before", r.vertices_before},
              {"points_after", r.vertices_after},
              {"evaluations", r.evaluations},
              {"reproduced", reproduced},
              {"harness", detail},
              {"normal_err_deg", found.normal_err_deg},
              {"depth_err_rel", found.depth_err_rel},
              {"point_err_rel", found.point_err_rel},
              {"message", found.message}}
      .dump();
}

// The leading comment of a shrunk closed-form scene (impact, landing kinds): where it was
// found, what the backend does on it, how it was shrunk (`shrunk`), how to reproduce it.
std::string closed_form_header(const std::string& kind, uint64_t seed, long count, uint64_t index,
                               const Json& g, const BackendOutcome& found,
                               const std::string& shrunk) {
  const std::string backend = g["backend"], sig = g["signature"];
  std::ostringstream h;
  h << "# Found by `rbx explore --kind " << kind << " --seed " << seed << " --count " << count
    << "`: sample " << index << ", group '" << sig << "',\n# " << g["count"].get<long>()
    << " samples. " << backend << " against the closed form: " << describe(found) << ".\n"
    << "# Shrunk " << shrunk << ", while the disagreement stayed.\n"
    << "# Reproduce: rbx compare THIS_FILE --backends " << backend << "\n";
  return h.str();
}

// One impact group's shrink: the scene carries its closed form ([expect]) already.
std::string shrink_impact_group(const Json& g, uint64_t seed, long count, int budget) {
  const ImpactSample start = make_impact_sample(seed, g["first_sample"].get<uint64_t>());
  const std::string backend = g["backend"], sig = g["signature"];
  const ImpactShrinkResult r = shrink_impact(start, backend, sig, budget);
  BackendOutcome found;
  for (const BackendOutcome& b : r.outcome.backends)
    if (b.backend == backend) found = b;
  if (found.error.empty()) return Json{{"ok", false}}.dump();
  const std::string text =
      closed_form_header("impact", seed, count, start.index, g, found,
                         "from " + std::to_string(r.vertices_before) + " to " +
                             std::to_string(r.vertices_after) + " points (" +
                             std::to_string(r.steps_accepted) + " simplifications kept, " +
                             std::to_string(r.evaluations) + " tried)") +
      r.sample.text;
  std::string detail;
  bool reproduced = false;
  reproduced = harness_reproduces(text, "explore.toml", found, &detail);
  return Json{{"ok", true},
              {"text", text},
              {"points_before", r.vertices_before},
              {"points_after", r.vertices_after},
              {"evaluations", r.evaluations},
              {"reproduced", reproduced},
              {"harness", detail},
              {"phase", r.sample.phase},
              {"velocity_err_ke", found.velocity_err_ke},
              {"momentum_err_ke", found.momentum_err_ke},
              {"message", found.message}}
      .dump();
}

// One landing group's shrink, as the impact kind's.
std::string shrink_landing_group(const Json& g, uint64_t seed, long count, int budget) {
  const LandingSample start = make_landing_sample(seed, g["first_sample"].get<uint64_t>());
  const std::string backend = g["backend"], sig = g["signature"];
  const LandingShrinkResult r = shrink_landing(start, backend, sig, budget);
  BackendOutcome found;
  for (const BackendOutcome& b : r.outcome.backends)
    if (b.backend == backend) found = b;
  if (found.error.empty()) return Json{{"ok", false}}.dump();
  const std::string text =
      closed_form_header("landing", seed, count, start.index, g, found,
                         "toward round numbers (" + std::to_string(r.steps_accepted) +
                             " simplifications kept, " + std::to_string(r.evaluations) +
                             " tried)") +
      r.sample.text;
  std::string detail;
  const bool reproduced = harness_reproduces(text, "explore.toml", found, &detail);
  return Json{{"ok", true},
              {"text", text},
              {"evaluations", r.evaluations},
              {"reproduced", reproduced},
              {"harness", detail},
              {"phase", r.sample.phase},
              {"position_err_m", found.position_err_m},
              {"turn_rad", found.turn_rad},
              {"rest_time_err_s", found.rest_time_err_s},
              {"message", found.message}}
      .dump();
}

// Regression against a stored explore.json: 1 when a backend got worse.
int compare_baseline(const Json& now, const std::string& path) {
  Json old;
  try {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot read");
    old = Json::parse(in);
  } catch (const std::exception& e) {
    throw InputError(path + ": not a readable explore.json (" + e.what() + ")");
  }
  for (const char* key : {"seed", "count", "kind"})
    if (!old.contains(key) || old[key] != now[key])
      throw InputError(path + ": " + key + ": the baseline was run with " +
                       (old.contains(key) ? old[key].dump() : "nothing") + ", this run with " +
                       now[key].dump() + " (use the same --seed, --count and --kind)");
  int worse = 0;
  // Same seed set, same code: identical numbers; anything above round-off of the summary
  // (1e-12 relative) is a change.
  auto up = [](double was, double is) { return is > was + 1e-12 * std::abs(was) + 1e-300; };
  for (const auto& [name, b] : now["backends"].items()) {
    if (!old["backends"].contains(name)) {
      std::cout << "  new backend " << name << " (not in the baseline)\n";
      continue;
    }
    const Json& o = old["backends"][name];
    if (up(o["rate"], b["rate"])) {
      std::cout << "  WORSE " << name << ": disagreement rate " << o["rate"] << " -> " << b["rate"]
                << "\n";
      ++worse;
    }
    for (const char* m : kMetrics)
      for (const char* p : {"p50", "p90", "p99"})
        if (o["errors"].contains(m) && up(o["errors"][m][p], b["errors"][m][p])) {
          std::cout << "  WORSE " << name << ": " << m << " " << p << " " << o["errors"][m][p]
                    << " -> " << b["errors"][m][p] << "\n";
          ++worse;
        }
    std::map<std::string, double> was;
    for (const Json& g : o["groups"]) was[g["signature"]] = g["rate"];
    for (const Json& g : b["groups"]) {
      const double before = was.count(g["signature"]) ? was[g["signature"]] : 0.0;
      if (up(before, g["rate"])) {
        std::cout << "  WORSE " << name << ": '" << g["signature"].get<std::string>() << "' rate "
                  << before << " -> " << g["rate"] << "\n";
        ++worse;
      }
    }
  }
  std::cout << "rbx explore: " << (worse ? std::to_string(worse) + " regressions" : "no regression")
            << " against " << path << "\n";
  return worse ? 1 : 0;
}

// The disagreement groups of an explore result, one row each (both kinds).
std::string groups_table(const Json& j) {
  Table g({"backend", "signature", "count", "rate", "scene", "points", "reproduced"});
  for (const auto& [name, b] : j["backends"].items())
    for (const Json& x : b["groups"])
      g.add({name, x["signature"], std::to_string(x["count"].get<long>()), fmt_num(x["rate"], 3),
             x["scene"].is_string() ? x["scene"].get<std::string>() : std::string("-"),
             x.contains("points_before") ? std::to_string(x["points_before"].get<int>()) + " -> " +
                                               std::to_string(x["points_after"].get<int>())
                                         : std::string("-"),
             x.value("reproduced", false) ? "yes" : "no"});
  return g.markdown();
}

// A metric's p50 / p90 / p99 from a backend's "errors" object, `digits` significant digits.
std::string three(const Json& errors, const char* m, int digits = 2) {
  const Json& e = errors[m];
  return fmt_num(e["p50"], digits) + " / " + fmt_num(e["p90"], digits) + " / " +
         fmt_num(e["p99"], digits);
}

// The table of disagreement rates by the quarter of its step the first contact falls in.
std::string phase_table(const Json& j) {
  Table ph({"backend", "0-25 %", "25-50 %", "50-75 %", "75-100 %"});
  for (const auto& [name, b] : j["backends"].items()) {
    std::vector<std::string> row = {name};
    for (const Json& q : b["by_phase_quarter"])
      row.push_back(fmt_num(q["rate"], 3) + " (" + std::to_string(q["samples"].get<long>()) + ")");
    ph.add(row);
  }
  return ph.markdown();
}

std::string markdown_impact(const Json& j) {
  std::ostringstream o;
  o << "# rbx explore: " << j["count"] << " random single-point impacts, seed " << j["seed"]
    << "\n\n"
    << "Every sample is one body (a box or a hull of 4 to 60 points) hitting a box, free or "
       "static, at one vertex on a face, with restitution e in [0.2, 1], no friction, no "
       "gravity, first contact 2 to 5 steps ahead at a random phase of its step. The closed form "
       "(single-point impulse at the exact oracle's point and normal, then torque-free flight) "
       "is the truth. A disagreement: a status error, no impulse at all (missed), a momentum "
       "error above 0.1 % in the energy norm (impulse), or a velocity error above it with the "
       "momenta right (spin: the free rotation after the impact).\n\n## Backends\n\n";
  Table t({"backend", "samples", "disagreements", "rate", "velocity err p50/p90/p99",
           "momentum err p50/p90/p99"});
  for (const auto& [name, b] : j["backends"].items())
    t.add({name, std::to_string(b["samples"].get<long>()),
           std::to_string(b["disagreements"].get<long>()), fmt_num(b["rate"], 3),
           three(b["errors"], "velocity_err_ke"), three(b["errors"], "momentum_err_ke")});
  o << t.markdown();
  o << "\n## Disagreement rate by the phase of the contact within its step\n\nThe first contact "
       "falls at this fraction of the step that detects it (0 %: at the step's start, so the "
       "bodies overlap by a whole step of approach when it is seen).\n\n";
  o << phase_table(j);
  o << "\n## Disagreement groups\n\nSignature: backend, shape classes of A and B (static: B "
       "is static), the contact's features, the kind of error. Each group's first sample was "
       "shrunk to the scene named; `reproduced` says whether `rbx compare` shows the velocity "
       "error on it.\n\n";
  o << groups_table(j);
  return o.str();
}

std::string markdown_landing(const Json& j) {
  std::ostringstream o;
  o << "# rbx explore: " << j["count"] << " random flat landings with friction, seed " << j["seed"]
    << "\n\n"
    << "Every sample is a box (sides 0.2 to 2 m, mass 0.1 to 10 kg, any yaw) landing flat on a "
       "static floor, e = 0, mu in [0.1, 1], falling at 0.2 to 2 m/s and sliding at 0.05 to "
       "1.5 m/s, under gravity, first touch 2 to 5 steps ahead at a random phase of its step; "
       "its height is drawn so that it cannot tip (mu sz <= 0.8 min(sx, sy)). The closed form "
       "(landing impulse J = m vn, friction impulse min(mu J, m |v_h|), a slide decelerating at "
       "mu g to rest, no turn) is the truth at the end of the run, 0.1 s or more after the rest. "
       "A disagreement: a status error, a turn above 1e-3 rad (turn), or a resting centre more "
       "than 1 mm from the closed form, horizontally (position). Time to rest: when the "
       "horizontal speed falls below 1 mm/s for good, read from every step (one step's "
       "resolution); reported, not marked. Velocity error: the final velocities in the energy "
       "norm against the initial kinetic energy.\n\n## Backends\n\n";
  Table t({"backend", "samples", "disagreements", "rate", "position err p50/p90/p99 (m)",
           "turn p50/p90/p99 (rad)", "rest time err p50/p99 (s)", "velocity err p99"});
  for (const auto& [name, b] : j["backends"].items()) {
    const Json& e = b["errors"];
    t.add(
        {name, std::to_string(b["samples"].get<long>()),
         std::to_string(b["disagreements"].get<long>()), fmt_num(b["rate"], 3),
         three(e, "position_err_m"), three(e, "turn_rad"),
         fmt_num(e["rest_time_err_s"]["p50"], 2) + " / " + fmt_num(e["rest_time_err_s"]["p99"], 2),
         fmt_num(e["velocity_err_ke"]["p99"], 2)});
  }
  o << t.markdown();
  o << "\n## Disagreement rate by the phase of the first touch within its step\n\nThe first "
       "touch falls at this fraction of the step that detects it (0 %: at the step's start).\n\n";
  o << phase_table(j);
  o << "\n## Disagreement groups\n\nSignature: backend, box-floor, whether the base slides on "
       "after the landing (slides) or the landing stops it (sticks), the kind of error. Each "
       "group's first sample was shrunk to the scene named; `reproduced` says whether `rbx "
       "compare` shows the same final position or turn on it.\n\n";
  o << groups_table(j);
  return o.str();
}

std::string markdown(const Json& j, bool have_figure) {
  if (j["kind"] == "impact") return markdown_impact(j);
  if (j["kind"] == "landing") return markdown_landing(j);
  std::ostringstream o;
  o << "# rbx explore: " << j["count"] << " random contact pairs, seed " << j["seed"] << "\n\n"
    << "Every sample is a random convex pair (boxes, hulls of 4 to 2,000 points, slivers; size "
       "ratios up to 1e3) at a pose biased toward hard cases, checked against the exact oracle. A "
       "disagreement is a status error, a touching mismatch beyond 1e-9 of the smaller body, a "
       "normal more than 1 degree off (ties counted as right), or a depth or point more than 1 % "
       "of the smaller body off.\n\n";
  o << "## Backends\n\n";
  Table t({"backend", "samples", "disagreements", "rate", "normal p50/p90/p99 (deg)",
           "depth p50/p90/p99 (rel)", "point p99 (rel)"});
  for (const auto& [name, b] : j["backends"].items()) {
    const Json& e = b["errors"];
    t.add({name, std::to_string(b["samples"].get<long>()),
           std::to_string(b["disagreements"].get<long>()), fmt_num(b["rate"], 3),
           three(e, "normal_err_deg"), three(e, "depth_err_rel"),
           fmt_num(e["point_err_rel"]["p99"], 2)});
  }
  o << t.markdown();
  if (have_figure) o << "\n![error distributions per backend](explore_errors.png)\n";
  o << "\n## Disagreement groups\n\nSignature: backend, shape classes of A and B, the exact "
       "oracle's axis (face_a, face_b, edge_edge, or separated), the kind of error. Each group's "
       "first sample was shrunk to the scene named; `reproduced` says whether `rbx compare` shows "
       "the same disagreement on it.\n\n";
  o << groups_table(j);
  return o.str();
}

}  // namespace

int explore_command(const ExploreOptions& opt) {
  ParallelRun par(opt.threads);
  if (opt.count <= 0)
    throw InputError("rbx explore: --count: must be > 0, got " + std::to_string(opt.count));
  if (opt.kind != "contact" && opt.kind != "impact" && opt.kind != "landing")
    throw InputError("rbx explore: --kind: must be contact, impact or landing, got '" + opt.kind +
                     "'");
  const bool impact = opt.kind == "impact", landing = opt.kind == "landing";
  const std::vector<std::string> names = subject_backends(opt.backends, opt.kind);
  const uint64_t seed = opt.seed;
  const size_t count = static_cast<size_t>(opt.count);

  // 1. Every sample, spread over ranks and threads; results in index order on rank 0.
  Stopwatch clock;
  long skipped_large = 0;
  const std::vector<std::string> raw = par.map(count, [&](size_t i) -> std::string {
    SampleOutcome o;
    o.index = i;
    try {
      if (impact) return encode(evaluate_impact_sample(make_impact_sample(seed, i), names));
      if (landing) return encode(evaluate_landing_sample(make_landing_sample(seed, i), names));
      const ContactSample s = make_contact_sample(seed, i);
      if (opt.bench) {
        // Throughput is stated on hulls under 100 points: larger ones are left out here.
        if (s.a.points.size() >= 100 || s.b.points.size() >= 100) return "";
      }
      o = evaluate_contact_sample(s, names);
    } catch (const std::exception& e) {
      o.pose_class = "invalid";
      o.feature = std::string("generation failed: ") + e.what();
    }
    return encode(o);
  });
  const double sampling_s = clock.seconds();

  if (opt.bench) {
    int code = 0;
    if (par.root()) {
      long done = 0;
      for (const std::string& r : raw) done += r.empty() ? 0 : 1;
      skipped_large = static_cast<long>(raw.size()) - done;
      const double cores = static_cast<double>(par.ranks()) * par.threads();
      std::cout << "rbx explore --bench: " << done << " samples (" << skipped_large
                << " with a hull of 100+ points left out) through exact";
      for (const std::string& n : names) std::cout << ", " << n;
      std::cout << " in " << fmt_num(sampling_s, 4) << " s on " << par.ranks() << " rank(s) x "
                << par.threads() << " thread(s): " << fmt_num(done / sampling_s * 60.0, 4)
                << " samples/min, " << fmt_num(done / sampling_s * 60.0 / cores, 4)
                << " per core per minute\n";
    }
    (void)code;
    return 0;
  }

  // 2. Rank 0 tallies: per backend, disagreements by signature and the error distributions.
  std::map<std::string, BackendTally> tally;
  std::map<std::string, long> pose_classes;
  long invalid = 0;
  std::string first_invalid;  // the first failed sample's message
  Json groups = Json::array();
  if (par.root()) {
    for (const std::string& n : names) tally[n];
    for (const std::string& text : raw) {
      const SampleOutcome s = decode(text);
      if (s.pose_class == "invalid") {
        if (invalid++ == 0) first_invalid = s.feature;
        continue;
      }
      ++pose_classes[s.pose_class];
      for (const BackendOutcome& b : s.backends) {
        BackendTally& t = tally[b.backend];
        ++t.samples;
        if (s.phase >= 0) {
          const int q = std::min(3, static_cast<int>(s.phase * 4));
          ++t.phase_samples[q];
          t.phase_disagreements[q] += b.error.empty() ? 0 : 1;
        }
        if (b.measured)
          for (const std::string& m : metrics_of(opt.kind))
            t.values[m].push_back(metric_value(b, m));
        if (b.error.empty()) continue;
        ++t.disagreements;
        const std::string sig = signature(s, b);
        if (t.by_signature[sig]++ == 0) {
          t.first_index[sig] = s.index;
          t.first_outcome[sig] = b;
        }
      }
    }
    for (const std::string& n : names)
      for (const auto& [sig, c] : tally[n].by_signature)
        groups.push_back({{"backend", n},
                          {"signature", sig},
                          {"count", c},
                          {"first_sample", tally[n].first_index[sig]}});
  }

  // 3. Each group shrunk, spread over ranks and threads like the samples.
  clock = Stopwatch();
  const Json all_groups = Json::parse(par.broadcast(groups.dump()));
  const std::vector<std::string> shrunk = par.map(all_groups.size(), [&](size_t k) {
    try {
      if (impact)
        return shrink_impact_group(all_groups[k], seed, opt.count,
                                   std::min(opt.shrink_budget, 120));
      if (landing)
        return shrink_landing_group(all_groups[k], seed, opt.count,
                                    std::min(opt.shrink_budget, 60));
      return shrink_group(all_groups[k], seed, opt.count, opt.shrink_budget);
    } catch (const std::exception& e) {
      return Json{{"ok", false}, {"message", e.what()}}.dump();
    }
  });
  const double shrinking_s = clock.seconds();
  if (!par.root()) return std::atoi(par.broadcast("").c_str());

  // 4. Outputs, on rank 0 only.
  const fs::path out = opt.out.empty() ? fs::path("reports/explore") : fs::path(opt.out);
  fs::create_directories(out / "scenes");
  for (const auto& f : fs::directory_iterator(out / "scenes"))
    if (f.path().extension() == ".toml") fs::remove(f.path());
  Json j;
  j["kind"] = opt.kind;
  j["seed"] = seed;
  j["count"] = opt.count;
  j["backends_run"] = names;
  j["invalid_samples"] = invalid;
  j["pose_classes"] = pose_classes;
  j["backends"] = Json::object();
  std::map<std::string, size_t> group_of;  // signature -> index in all_groups
  for (size_t k = 0; k < all_groups.size(); ++k) group_of[all_groups[k]["signature"]] = k;
  long reproduced = 0, written = 0;
  for (const std::string& n : names) {
    BackendTally& t = tally[n];
    Json b;
    b["samples"] = t.samples;
    b["disagreements"] = t.disagreements;
    b["rate"] = t.samples ? static_cast<double>(t.disagreements) / t.samples : 0.0;
    b["errors"] = Json::object();
    for (const std::string& m : metrics_of(opt.kind)) {
      std::vector<double>& v = t.values[m];
      std::sort(v.begin(), v.end());
      Json q = Json::array();
      for (int p = 0; p <= 100; p += 5) q.push_back(percentile(v, p));
      b["errors"][m] = {{"n", v.size()},
                        {"p50", percentile(v, 50)},
                        {"p90", percentile(v, 90)},
                        {"p99", percentile(v, 99)},
                        {"max", percentile(v, 100)},
                        {"quantiles_every_5", q}};
    }
    if (impact || landing) {
      b["by_phase_quarter"] = Json::array();
      for (int q = 0; q < 4; ++q)
        b["by_phase_quarter"].push_back(
            {{"phase", std::to_string(q * 25) + "-" + std::to_string(q * 25 + 25) + " %"},
             {"samples", t.phase_samples[q]},
             {"disagreements", t.phase_disagreements[q]},
             {"rate", t.phase_samples[q]
                          ? static_cast<double>(t.phase_disagreements[q]) / t.phase_samples[q]
                          : 0.0}});
    }
    b["groups"] = Json::array();
    std::vector<std::pair<long, std::string>> order;
    for (const auto& [sig, c] : t.by_signature) order.push_back({-c, sig});
    std::sort(order.begin(), order.end());
    for (const auto& [neg, sig] : order) {
      const BackendOutcome& first = t.first_outcome[sig];
      Json g = {{"signature", sig},
                {"count", -neg},
                {"rate", static_cast<double>(-neg) / t.samples},
                {"first_sample", t.first_index[sig]},
                {"first_error", describe(first)}};
      const Json r = Json::parse(shrunk[group_of[sig]]);
      if (r.value("ok", false)) {
        const std::string file = "scenes/" + file_stem(sig) + ".toml";
        write_text((out / file).string(), r["text"].get<std::string>());
        ++written;
        g["scene"] = file;
        for (const char* k :
             {"points_before", "points_after", "evaluations", "reproduced", "harness"})
          if (r.contains(k)) g[k] = r[k];  // a landing's box has 8 points throughout: no count
        if (impact) {
          g["shrunk_error"] = {{"velocity_err_ke", r["velocity_err_ke"]},
                               {"momentum_err_ke", r["momentum_err_ke"]},
                               {"phase", r["phase"]}};
        } else if (landing) {
          g["shrunk_error"] = {{"position_err_m", r["position_err_m"]},
                               {"turn_rad", r["turn_rad"]},
                               {"rest_time_err_s", r["rest_time_err_s"]},
                               {"phase", r["phase"]}};
        } else {
          g["shrunk_error"] = {{"normal_err_deg", r["normal_err_deg"]},
                               {"depth_err_rel", r["depth_err_rel"]},
                               {"point_err_rel", r["point_err_rel"]}};
        }
        if (r["reproduced"].get<bool>()) ++reproduced;
      } else {
        g["scene"] = nullptr;
        g["shrink_failed"] = r.value("message", std::string("the scene text did not show it"));
      }
      b["groups"].push_back(g);
    }
    j["backends"][n] = b;
  }
  const double cores = static_cast<double>(par.ranks()) * par.threads();
  j["timing"] = {{"runtime_s", sampling_s + shrinking_s},
                 {"sampling_s", sampling_s},
                 {"shrinking_s", shrinking_s},
                 {"samples_per_min_per_core", opt.count / sampling_s * 60.0 / cores},
                 {"ranks", par.ranks()},
                 {"threads_per_rank", par.threads()}};
  write_json((out / "explore.json").string(), j);

  // The figure (matplotlib from Debian, as `rbx report`), then the page that shows it.
  bool figure = false;
  const std::string script =
      std::string(RBX_DEFAULT_SOURCE_DIR) + "/comparisons/output/explore_plots.py";
  if (fs::exists("/usr/bin/python3") && !opt.no_figure) {
    const std::string cmd = "/usr/bin/python3 '" + script + "' '" + out.string() + "' > '" +
                            (out / "figures.log").string() + "' 2>&1";
    figure = std::system(cmd.c_str()) == 0;
  }
  write_text((out / "explore.md").string(), markdown(j, figure));
  std::cout << "rbx explore: " << opt.count << " samples, " << all_groups.size()
            << " disagreement groups, " << written << " scenes (" << reproduced
            << " reproduced by the harness) in " << fmt_num(sampling_s + shrinking_s, 3) << " s on "
            << par.ranks() << " rank(s) x " << par.threads() << " thread(s) -> " << out.string()
            << "/explore.{json,md}\n";
  // Samples that could not be made are said, never silently left out; none made at all is a
  // failed run.
  if (invalid > 0)
    std::cerr << "rbx explore: " << invalid << " of " << opt.count
              << " samples could not be made (first: " << first_invalid << ")\n";
  int code = invalid == static_cast<long>(opt.count) ? 1 : 0;
  try {
    if (!opt.baseline.empty()) code = std::max(code, compare_baseline(j, opt.baseline));
  } catch (const InputError&) {
    par.broadcast("2");  // the other ranks end with the same exit code
    throw;
  }
  par.broadcast(std::to_string(code));
  return code;
}

}  // namespace rbx
