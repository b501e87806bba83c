// `rbx explore`'s campaign: random samples of one kind against their truth over every core or
// MPI rank, disagreements tallied and grouped by signature, each group's first sample shrunk to
// a scene; and the regression check of a campaign against a stored one.
#include "comparisons/eval/explore_campaign.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/select_backends.h"
#include "comparisons/eval/toi_query.h"
#include "comparisons/scene/scene_file.h"
#include "engine/bounding.h"
#include "engine/format.h"
#include "reference/exact.h"

namespace rbx {

using explore_detail::describe_outcome;
using explore_detail::shrink_group;

namespace {

const char* const kMetrics[] = {"normal_err_deg",   "depth_err_rel",   "point_err_rel",
                                "coverage_err_rel", "velocity_err_ke", "momentum_err_ke",
                                "position_err_m",   "turn_rad",        "rest_time_err_s",
                                "distance_err_rel", "witness_err_rel", "time_err"};

// The metrics of one kind of sample.
std::vector<std::string> metrics_of(const std::string& kind) {
  if (kind == "impact") return {"velocity_err_ke", "momentum_err_ke"};
  if (kind == "landing" || kind == "slide")
    return {"position_err_m", "turn_rad", "velocity_err_ke", "rest_time_err_s"};
  if (kind == "tunnel") return {"velocity_err_ke", "position_err_m"};
  if (kind == "distance") return {"distance_err_rel", "witness_err_rel"};
  if (kind == "toi") return {"time_err"};
  return {"normal_err_deg", "depth_err_rel", "point_err_rel", "coverage_err_rel"};
}

// One metric of a backend's outcome, by its name in explore.json.
double metric_value(const BackendOutcome& b, const std::string& m) {
  if (m == "normal_err_deg") return b.normal_err_deg;
  if (m == "depth_err_rel") return b.depth_err_rel;
  if (m == "point_err_rel") return b.point_err_rel;
  if (m == "coverage_err_rel") return b.coverage_err_rel;
  if (m == "velocity_err_ke") return b.velocity_err_ke;
  if (m == "momentum_err_ke") return b.momentum_err_ke;
  if (m == "position_err_m") return b.position_err_m;
  if (m == "turn_rad") return b.turn_rad;
  if (m == "distance_err_rel") return b.distance_err_rel;
  if (m == "witness_err_rel") return b.witness_err_rel;
  if (m == "time_err") return b.time_err;
  return b.rest_time_err_s;
}

std::vector<std::string> subject_backends(const std::string& list, const std::string& kind) {
  std::vector<std::string> names;
  if (list.empty() || list == "all") {
    // Every backend with a contact query (contact kind), a distance query (distance kind), a
    // time-of-impact query (toi kind: its variants' rows come with it) or a
    // dynamics run (the others); `exact` is the truth, not a subject.
    for (const Backend& b : backends()) {
      const bool serves = kind == "contact"    ? static_cast<bool>(b.contact)
                          : kind == "distance" ? static_cast<bool>(b.distance)
                          : kind == "toi"      ? static_cast<bool>(b.toi)
                                               : static_cast<bool>(b.dynamics);
      if (serves && b.name != "exact") names.push_back(b.name);
    }
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

// Whether the pair of shape classes (a, b) is one of `pairs`, in either order.
bool keeps_shapes(const std::vector<std::string>& pairs, const std::string& a,
                  const std::string& b) {
  return std::find(pairs.begin(), pairs.end(), a + "-" + b) != pairs.end() ||
         std::find(pairs.begin(), pairs.end(), b + "-" + a) != pairs.end();
}

// Every sample, spread over ranks and threads; encoded outcomes in index order on rank 0.
// `bench`: contact samples with a hull of 100+ points are left out (encoded as "").
std::vector<std::string> sample_all(const ExploreSettings& set,
                                    const std::vector<std::string>& names, const ParallelRun& par,
                                    bool bench) {
  return par.map(static_cast<size_t>(set.count), [&](size_t i) -> std::string {
    SampleOutcome o;
    o.index = i;
    try {
      if (set.kind == "impact")
        return encode(evaluate_impact_sample(make_impact_sample(set.seed, i), names));
      if (set.kind == "landing")
        return encode(evaluate_landing_sample(make_landing_sample(set.seed, i), names));
      if (set.kind == "slide")
        return encode(evaluate_slide_sample(make_slide_sample(set.seed, i), names));
      if (set.kind == "tunnel")
        return encode(evaluate_tunnel_sample(make_tunnel_sample(set.seed, i), names));
      if (set.kind == "distance")
        return encode(evaluate_distance_sample(make_distance_sample(set.seed, i), names));
      if (set.kind == "toi")
        return encode(evaluate_toi_sample(make_toi_sample(set.seed, i), names));
      const ContactSample s = make_contact_sample(set.seed, i);
      if (bench && (s.a.points.size() >= 100 || s.b.points.size() >= 100)) return "";
      if (!set.shapes.empty() && !keeps_shapes(set.shapes, s.a.shape_class, s.b.shape_class))
        return "";
      o = evaluate_contact_sample(s, names);
    } catch (const std::exception& e) {
      o.pose_class = "invalid";
      o.feature = std::string("generation failed: ") + e.what();
    }
    return encode(o);
  });
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
  long coverage_misses = 0;  // contact: measured answers whose points miss the patch by > 1 %
};

// Everything rank 0 counts over the samples.
struct Tallies {
  std::map<std::string, BackendTally> backend;
  std::map<std::string, long> pose_classes;
  long invalid = 0;
  std::string first_invalid;  // the first failed sample's message
};

// Per backend: disagreements by signature and the error distributions.
Tallies tally_samples(const std::vector<std::string>& raw, const std::vector<std::string>& names,
                      const std::string& kind) {
  Tallies t;
  for (const std::string& n : names) t.backend[n];
  for (const std::string& text : raw) {
    if (text.empty()) continue;  // left out: not of the shape classes asked for
    const SampleOutcome s = decode(text);
    if (s.pose_class == "invalid") {
      if (t.invalid++ == 0) t.first_invalid = s.feature;
      continue;
    }
    ++t.pose_classes[s.pose_class];
    for (const BackendOutcome& b : s.backends) {
      BackendTally& bt = t.backend[b.backend];
      ++bt.samples;
      if (s.phase >= 0) {
        const int q = std::min(3, static_cast<int>(s.phase * 4));
        ++bt.phase_samples[q];
        bt.phase_disagreements[q] += b.error.empty() ? 0 : 1;
      }
      if (b.measured)
        for (const std::string& m : metrics_of(kind)) bt.values[m].push_back(metric_value(b, m));
      if (b.measured && b.coverage_err_rel > kMarkDepthRel) ++bt.coverage_misses;
      if (b.error.empty()) continue;
      ++bt.disagreements;
      const std::string sig = signature(s, b);
      if (bt.by_signature[sig]++ == 0) {
        bt.first_index[sig] = s.index;
        bt.first_outcome[sig] = b;
      }
    }
  }
  return t;
}

// The disagreement groups to shrink: backend, signature, count, first sample.
Json disagreement_groups(Tallies& t, const std::vector<std::string>& names) {
  Json groups = Json::array();
  for (const std::string& n : names)
    for (const auto& [sig, c] : t.backend[n].by_signature)
      groups.push_back({{"backend", n},
                        {"signature", sig},
                        {"count", c},
                        {"first_sample", t.backend[n].first_index[sig]}});
  return groups;
}

// Each group shrunk, spread over ranks and threads like the samples.
std::vector<std::string> shrink_groups(const Json& groups, const ExploreSettings& set,
                                       const ParallelRun& par) {
  return par.map(groups.size(), [&](size_t k) { return shrink_group(groups[k], set); });
}

// A backend's error distributions: n, p50, p90, p99, max and every 5th percentile.
Json error_distributions(BackendTally& t, const std::string& kind) {
  Json errors = Json::object();
  for (const std::string& m : metrics_of(kind)) {
    std::vector<double>& v = t.values[m];
    std::sort(v.begin(), v.end());
    Json q = Json::array();
    for (int p = 0; p <= 100; p += 5) q.push_back(nearest_rank_percentile(v, p));
    errors[m] = {{"n", v.size()},
                 {"p50", nearest_rank_percentile(v, 50)},
                 {"p90", nearest_rank_percentile(v, 90)},
                 {"p99", nearest_rank_percentile(v, 99)},
                 {"max", nearest_rank_percentile(v, 100)},
                 {"quantiles_every_5", q}};
  }
  return errors;
}

// Samples and disagreements by the quarter of its step the first contact falls in.
Json phase_quarters(const BackendTally& t) {
  Json out = Json::array();
  for (int q = 0; q < 4; ++q)
    out.push_back({{"phase", std::to_string(q * 25) + "-" + std::to_string(q * 25 + 25) + " %"},
                   {"samples", t.phase_samples[q]},
                   {"disagreements", t.phase_disagreements[q]},
                   {"rate", t.phase_samples[q]
                                ? static_cast<double>(t.phase_disagreements[q]) / t.phase_samples[q]
                                : 0.0}});
  return out;
}

// One group of explore.json from its tally and its shrink's answer `r`; a shrunk scene goes
// into `campaign.scenes`.
Json group_json(const std::string& sig, long count, const BackendTally& t, const Json& r,
                const std::string& kind, ExploreCampaign& campaign) {
  Json g = {{"signature", sig},
            {"count", count},
            {"rate", static_cast<double>(count) / t.samples},
            {"first_sample", t.first_index.at(sig)},
            {"first_error", describe_outcome(t.first_outcome.at(sig))}};
  if (!r.value("ok", false)) {
    g["scene"] = nullptr;
    g["shrink_failed"] = r.value("message", std::string("the scene text did not show it"));
    return g;
  }
  const std::string file = "scenes/" + file_stem(sig) + ".toml";
  campaign.scenes.emplace_back(file, r["text"].get<std::string>());
  g["scene"] = file;
  for (const char* k : {"points_before", "points_after", "evaluations", "reproduced", "harness"})
    if (r.contains(k)) g[k] = r[k];  // a landing's box has 8 points throughout: no count
  if (kind == "impact") {
    g["shrunk_error"] = {{"velocity_err_ke", r["velocity_err_ke"]},
                         {"momentum_err_ke", r["momentum_err_ke"]},
                         {"phase", r["phase"]}};
  } else if (kind == "landing") {
    g["shrunk_error"] = {{"position_err_m", r["position_err_m"]},
                         {"turn_rad", r["turn_rad"]},
                         {"rest_time_err_s", r["rest_time_err_s"]},
                         {"phase", r["phase"]}};
  } else if (kind == "tunnel") {
    g["shrunk_error"] = {{"velocity_err_ke", r["velocity_err_ke"]},
                         {"position_err_m", r["position_err_m"]},
                         {"phase", r["phase"]}};
  } else if (kind == "distance") {
    g["shrunk_error"] = {{"distance_err_rel", r["distance_err_rel"]},
                         {"witness_err_rel", r["witness_err_rel"]}};
  } else if (kind == "toi") {
    g["shrunk_error"] = {{"time_err", r["time_err"]}};
  } else if (kind == "slide") {
    g["shrunk_error"] = {{"position_err_m", r["position_err_m"]},
                         {"turn_rad", r["turn_rad"]},
                         {"rest_time_err_s", r["rest_time_err_s"]}};
  } else {
    g["shrunk_error"] = {{"normal_err_deg", r["normal_err_deg"]},
                         {"depth_err_rel", r["depth_err_rel"]},
                         {"point_err_rel", r["point_err_rel"]}};
  }
  if (r["reproduced"].get<bool>()) ++campaign.reproduced;
  return g;
}

// One backend of explore.json: counts, rate, error distributions, phase quarters, groups
// (largest first).
Json backend_json(BackendTally& t, const std::string& kind, const Json& groups,
                  const std::vector<std::string>& shrunk, ExploreCampaign& campaign) {
  std::map<std::string, size_t> group_of;  // signature -> index in groups
  for (size_t k = 0; k < groups.size(); ++k) group_of[groups[k]["signature"]] = k;
  Json b;
  b["samples"] = t.samples;
  b["disagreements"] = t.disagreements;
  b["rate"] = t.samples ? static_cast<double>(t.disagreements) / t.samples : 0.0;
  b["errors"] = error_distributions(t, kind);
  if (kind == "contact") b["coverage_misses"] = t.coverage_misses;
  if (kind == "impact" || kind == "landing" || kind == "tunnel")
    b["by_phase_quarter"] = phase_quarters(t);
  b["groups"] = Json::array();
  std::vector<std::pair<long, std::string>> order;
  for (const auto& [sig, c] : t.by_signature) order.push_back({-c, sig});
  std::sort(order.begin(), order.end());
  for (const auto& [neg, sig] : order)
    b["groups"].push_back(
        group_json(sig, -neg, t, Json::parse(shrunk[group_of[sig]]), kind, campaign));
  return b;
}

}  // namespace

double nearest_rank_percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0.0;
  const size_t k = static_cast<size_t>(std::ceil(p / 100.0 * sorted.size()));
  return sorted[std::min(sorted.size() - 1, k == 0 ? 0 : k - 1)];
}

ExploreThroughput explore_throughput(const ExploreSettings& set, const ParallelRun& par) {
  ExploreThroughput t;
  t.backends = subject_backends(set.backends, set.kind);
  Stopwatch clock;
  const std::vector<std::string> raw = sample_all(set, t.backends, par, true);
  t.seconds = clock.seconds();
  for (const std::string& r : raw) t.done += r.empty() ? 0 : 1;
  t.left_out = static_cast<long>(raw.size()) - t.done;
  return t;
}

ExploreCampaign run_explore(const ExploreSettings& set, const ParallelRun& par) {
  ExploreCampaign c;
  const std::vector<std::string> names = subject_backends(set.backends, set.kind);
  Stopwatch clock;
  const std::vector<std::string> raw = sample_all(set, names, par, false);
  c.sampling_s = clock.seconds();
  // The toi kind's rows: each backend's query, then its variants' ("bullet-hull/gjk-cast").
  std::vector<std::string> rows;
  if (set.kind == "toi") {
    for (const ToiSubject& s : toi_subjects(names))
      if (s.fn) rows.push_back(s.name);
  } else {
    rows = names;
  }
  Tallies t;
  Json groups = Json::array();
  if (par.root()) {
    t = tally_samples(raw, rows, set.kind);
    groups = disagreement_groups(t, rows);
  }
  clock = Stopwatch();
  const Json all_groups = Json::parse(par.broadcast(groups.dump()));
  const std::vector<std::string> shrunk = shrink_groups(all_groups, set, par);
  c.shrinking_s = clock.seconds();
  if (!par.root()) return c;
  c.groups = static_cast<long>(all_groups.size());
  c.invalid = t.invalid;
  c.first_invalid = t.first_invalid;
  Json& j = c.result;
  j["kind"] = set.kind;
  j["seed"] = set.seed;
  j["count"] = set.count;
  if (!set.shapes.empty()) {
    j["shapes"] = set.shapes;
    j["samples_kept"] = static_cast<long>(
        std::count_if(raw.begin(), raw.end(), [](const std::string& r) { return !r.empty(); }));
  }
  j["backends_run"] = names;
  j["invalid_samples"] = t.invalid;
  j["pose_classes"] = t.pose_classes;
  j["backends"] = Json::object();
  for (const std::string& n : rows)
    j["backends"][n] = backend_json(t.backend[n], set.kind, all_groups, shrunk, c);
  const double cores = static_cast<double>(par.ranks()) * par.threads();
  j["timing"] = {{"runtime_s", c.sampling_s + c.shrinking_s},
                 {"sampling_s", c.sampling_s},
                 {"shrinking_s", c.shrinking_s},
                 {"samples_per_min_per_core", set.count / c.sampling_s * 60.0 / cores},
                 {"ranks", par.ranks()},
                 {"threads_per_rank", par.threads()}};
  c.summary = read_explore_summary(j);
  return c;
}

void check_shape_pairs(const std::vector<std::string>& pairs, const std::string& kind) {
  if (pairs.empty()) return;
  if (kind != "contact")
    throw InputError("rbx explore: --shapes: only for --kind contact (the " + kind +
                     " kind draws its own boxes)");
  const std::vector<std::string> classes = {"box", "hull", "sliver"};
  for (const std::string& p : pairs) {
    const size_t dash = p.find('-');
    const auto known = [&](const std::string& c) {
      return std::find(classes.begin(), classes.end(), c) != classes.end();
    };
    if (dash == std::string::npos || !known(p.substr(0, dash)) || !known(p.substr(dash + 1)))
      throw InputError("rbx explore: --shapes: \"" + p +
                       "\" is not a pair of shape classes; write e.g. box-box,box-hull (classes: "
                       "box, hull, sliver)");
  }
}

std::vector<std::string> explore_regressions(const Json& now, const std::string& path, int& worse) {
  std::vector<std::string> lines;
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
  if (old.value("shapes", Json::array()) != now.value("shapes", Json::array()))
    throw InputError(path + ": shapes: the baseline was run with " +
                     old.value("shapes", Json::array()).dump() + ", this run with " +
                     now.value("shapes", Json::array()).dump() + " (use the same --shapes)");
  worse = 0;
  // Same seed set, same code: identical numbers; anything above round-off of the summary
  // (1e-12 relative) is a change.
  auto up = [](double was, double is) { return is > was + 1e-12 * std::abs(was) + 1e-300; };
  for (const auto& [name, b] : now["backends"].items()) {
    if (!old["backends"].contains(name)) {
      lines.push_back("new backend " + name + " (not in the baseline)");
      continue;
    }
    const Json& o = old["backends"][name];
    if (up(o["rate"], b["rate"])) {
      lines.push_back("WORSE " + name + ": disagreement rate " + o["rate"].dump() + " -> " +
                      b["rate"].dump());
      ++worse;
    }
    for (const char* m : kMetrics)
      for (const char* p : {"p50", "p90", "p99"})
        if (o["errors"].contains(m) && up(o["errors"][m][p], b["errors"][m][p])) {
          lines.push_back("WORSE " + name + ": " + m + " " + p + " " + o["errors"][m][p].dump() +
                          " -> " + b["errors"][m][p].dump());
          ++worse;
        }
    std::map<std::string, double> was;
    for (const Json& g : o["groups"]) was[g["signature"]] = g["rate"];
    for (const Json& g : b["groups"]) {
      const double before = was.count(g["signature"]) ? was[g["signature"]] : 0.0;
      if (up(before, g["rate"])) {
        std::ostringstream was_text;
        was_text << before;
        lines.push_back("WORSE " + name + ": '" + g["signature"].get<std::string>() + "' rate " +
                        was_text.str() + " -> " + g["rate"].dump());
        ++worse;
      }
    }
  }
  return lines;
}

}  // namespace rbx
