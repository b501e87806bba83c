#include "comparisons/eval/explore_check.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "comparisons/eval/distance_query.h"
#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_campaign.h"
#include "comparisons/eval/parallel.h"
#include "comparisons/eval/toi_query.h"
#include "comparisons/scene/scene_file.h"

namespace rbx {

namespace {

// The metrics of one family from its encoded outcomes.
void tally(const std::string& scene, const std::vector<std::string>& encoded,
           const std::vector<std::string>& error_names, const std::string& against,
           std::vector<ExploreCheckMetric>& out) {
  std::map<std::string, long> samples, disagreements;
  std::map<std::string, std::map<std::string, std::vector<double>>> values;
  for (const std::string& text : encoded) {
    const SampleOutcome o = decode(text);
    for (const BackendOutcome& b : o.backends) {
      ++samples[b.backend];
      if (!b.error.empty()) ++disagreements[b.backend];
      if (!b.measured) continue;
      values[b.backend]["normal_err_deg"].push_back(b.normal_err_deg);
      values[b.backend]["depth_err_rel"].push_back(b.depth_err_rel);
      values[b.backend]["coverage_err_rel"].push_back(b.coverage_err_rel);
      values[b.backend]["velocity_err_ke"].push_back(b.velocity_err_ke);
      values[b.backend]["position_err_m"].push_back(b.position_err_m);
      values[b.backend]["turn_rad"].push_back(b.turn_rad);
      values[b.backend]["rest_time_err_s"].push_back(b.rest_time_err_s);
      values[b.backend]["distance_err_rel"].push_back(b.distance_err_rel);
      values[b.backend]["witness_err_rel"].push_back(b.witness_err_rel);
      values[b.backend]["time_err"].push_back(b.time_err);
    }
  }
  for (const auto& [backend, n] : samples) {
    const double rate = static_cast<double>(disagreements[backend]) / static_cast<double>(n);
    out.push_back({scene, {"explore", backend, "", "disagreement_rate_err", rate, against}});
    for (const std::string& name : error_names) {
      std::vector<double> v = values[backend][name];
      std::sort(v.begin(), v.end());
      out.push_back(
          {scene,
           {"explore", backend, "", name + "_p50", nearest_rank_percentile(v, 50), against}});
      out.push_back(
          {scene,
           {"explore", backend, "", name + "_p90", nearest_rank_percentile(v, 90), against}});
    }
  }
}

// Each row of `f` timed on the family's first kQueryTimedSamples samples as `rbx distance` and
// `rbx toi` time theirs (every row interleaved on one sample, then the next), on this thread
// alone: the others have finished their samples.
void time_query_family(QueryFamily& f, const ExploreCheckSet& set,
                       const std::vector<std::string>& backends) {
  std::map<std::string, std::vector<double>> times;
  const int n = std::min<int>(kQueryTimedSamples, static_cast<int>(f.count));
  constexpr double kBudgetS = 0.002;  // per row and sample: 40 samples of 11 rows in a second
  for (int i = 0; i < n; ++i) {
    const uint64_t k = static_cast<uint64_t>(i);
    if (f.error == "time_err") {
      const ToiSample s = make_toi_sample(set.seed, k);
      const Scene scene = parse_scene(toi_scene_text(s), "explore.toml");
      const ToiComparison c = compare_tois(scene, backends, s.interval, kBudgetS);
      for (const ToiRow& r : c.pairs.at(0).rows)
        if (r.timing.rounds > 0) times[r.backend].push_back(r.timing.median_s);
    } else {
      const Scene scene =
          parse_scene(sample_scene_text(make_distance_sample(set.seed, k)), "explore.toml");
      const DistanceComparison c = compare_distances(scene, backends, kBudgetS);
      for (const DistanceRow& r : c.pairs.at(0).rows)
        if (r.timing.rounds > 0) times[r.backend].push_back(r.timing.median_s);
    }
  }
  for (QueryFamilyRow& r : f.rows) {
    std::vector<double>& t = times[r.backend];
    if (t.empty()) continue;
    std::sort(t.begin(), t.end());
    r.timed = static_cast<int>(t.size());
    r.time_s = nearest_rank_percentile(t, 50);
    r.time_q25_s = nearest_rank_percentile(t, 25);
    r.time_q75_s = nearest_rank_percentile(t, 75);
  }
}

}  // namespace

QueryFamily query_family(const std::string& scene, const std::string& error,
                         const std::vector<std::string>& encoded) {
  QueryFamily f{scene, error, static_cast<long>(encoded.size()), {}};
  std::map<std::string, QueryFamilyRow> rows;
  std::map<std::string, std::vector<double>> main, witness;
  std::map<std::string, std::map<std::string, std::vector<double>>> separations;
  for (const std::string& text : encoded) {
    const SampleOutcome o = decode(text);
    for (const BackendOutcome& b : o.backends) {
      QueryFamilyRow& r = rows[b.backend];
      r.backend = b.backend;
      ++r.samples;
      if (!b.error.empty()) {
        ++r.disagreements;
        auto k = std::find_if(r.kinds.begin(), r.kinds.end(),
                              [&](const QueryFamilyRow::Kind& x) { return x.name == b.error; });
        if (k == r.kinds.end())
          k = r.kinds.insert(r.kinds.end(), QueryFamilyRow::Kind{b.error, 0, o.index, 0.0, 0.0});
        ++k->count;
        if (b.error == "early" || b.error == "late")
          separations[b.backend][b.error].push_back(std::abs(b.separation_m));
      }
      if (!b.measured) continue;
      ++r.measured;
      if (error == "time_err" && b.error.empty() && b.time_err > kToiDisagree) ++r.grazing;
      main[b.backend].push_back(error == "time_err" ? b.time_err : b.distance_err_rel);
      witness[b.backend].push_back(b.witness_err_rel);
    }
  }
  for (auto& [name, r] : rows) {
    std::vector<double>& v = main[name];
    std::sort(v.begin(), v.end());
    for (int p = 0; p <= 100; p += 5) r.quantiles.push_back(nearest_rank_percentile(v, p));
    r.p50 = nearest_rank_percentile(v, 50);
    r.p90 = nearest_rank_percentile(v, 90);
    r.p99 = nearest_rank_percentile(v, 99);
    std::vector<double>& w = witness[name];
    std::sort(w.begin(), w.end());
    r.witness_p50 = nearest_rank_percentile(w, 50);
    r.witness_p90 = nearest_rank_percentile(w, 90);
    for (QueryFamilyRow::Kind& k : r.kinds) {
      std::vector<double>& sep = separations[name][k.name];
      if (sep.empty()) continue;
      std::sort(sep.begin(), sep.end());
      k.separation_p50 = nearest_rank_percentile(sep, 50);
      k.separation_max = sep.back();
    }
    std::stable_sort(r.kinds.begin(), r.kinds.end(),
                     [](const auto& x, const auto& y) { return x.count > y.count; });
    f.rows.push_back(r);
  }
  auto rate = [](const QueryFamilyRow& r) {
    return r.samples ? static_cast<double>(r.disagreements) / static_cast<double>(r.samples) : 1.0;
  };
  // Rows arrive in name order, which breaks the remaining ties.
  std::stable_sort(f.rows.begin(), f.rows.end(), [&](const auto& x, const auto& y) {
    if (rate(x) != rate(y)) return rate(x) < rate(y);
    return x.p50 < y.p50;
  });
  return f;
}

std::vector<ExploreCheckMetric> explore_check_metrics(
    const std::vector<std::string>& contact_backends,
    const std::vector<std::string>& impact_backends, const ExploreCheckSet& set,
    const std::vector<Backend>* table, const ParallelRun* given, const ResultCache* cache,
    std::vector<QueryFamily>* queries) {
  std::vector<ExploreCheckMetric> out;
  std::optional<ParallelRun> own;
  if (!given) own.emplace();
  const ParallelRun& run = given ? *given : *own;
  if (!contact_backends.empty() && set.contact > 0)
    tally("explore/contact",
          run.map(static_cast<size_t>(set.contact),
                  [&](size_t i) {
                    return encode(evaluate_contact_sample(make_contact_sample(set.seed, i),
                                                          contact_backends, table, cache));
                  }),
          {"normal_err_deg", "depth_err_rel", "coverage_err_rel"}, "exact", out);
  // The distance kind's subjects: the contact backends that have a distance query.
  std::vector<std::string> distance_backends;
  for (const std::string& name : contact_backends)
    if (const Backend* b = find_backend(name, table); b && b->distance)
      distance_backends.push_back(name);
  if (!distance_backends.empty() && set.distance > 0) {
    const std::vector<std::string> encoded =
        run.map(static_cast<size_t>(set.distance), [&](size_t i) {
          return encode(evaluate_distance_sample(make_distance_sample(set.seed, i),
                                                 distance_backends, table, cache));
        });
    tally("explore/distance", encoded, {"distance_err_rel", "witness_err_rel"}, "exact", out);
    if (queries && run.root()) {
      queries->push_back(query_family("explore/distance", "distance_err_rel", encoded));
      time_query_family(queries->back(), set, distance_backends);
    }
  }
  // The toi kind's subjects: the contact backends that have a time-of-impact query (their
  // variants' rows come with them).
  std::vector<std::string> toi_backends;
  for (const std::string& name : contact_backends)
    if (const Backend* b = find_backend(name, table); b && b->toi && name != "exact")
      toi_backends.push_back(name);
  if (!toi_backends.empty() && set.toi > 0) {
    const std::vector<std::string> encoded = run.map(static_cast<size_t>(set.toi), [&](size_t i) {
      return encode(evaluate_toi_sample(make_toi_sample(set.seed, i), toi_backends, cache));
    });
    tally("explore/toi", encoded, {"time_err"}, "exact", out);
    if (queries && run.root()) {
      queries->push_back(query_family("explore/toi", "time_err", encoded));
      time_query_family(queries->back(), set, toi_backends);
    }
  }
  if (!impact_backends.empty() && set.impact > 0)
    tally("explore/impact",
          run.map(static_cast<size_t>(set.impact),
                  [&](size_t i) {
                    return encode(evaluate_impact_sample(make_impact_sample(set.seed, i),
                                                         impact_backends, table, cache));
                  }),
          {"velocity_err_ke"}, "analytic", out);
  if (!impact_backends.empty() && set.landing > 0)
    tally("explore/landing",
          run.map(static_cast<size_t>(set.landing),
                  [&](size_t i) {
                    return encode(evaluate_landing_sample(make_landing_sample(set.seed, i),
                                                          impact_backends, table, cache));
                  }),
          {"position_err_m", "turn_rad"}, "analytic", out);
  if (!impact_backends.empty() && set.slide > 0)
    tally("explore/slide",
          run.map(static_cast<size_t>(set.slide),
                  [&](size_t i) {
                    return encode(evaluate_slide_sample(make_slide_sample(set.seed, i),
                                                        impact_backends, table, cache));
                  }),
          {"position_err_m", "turn_rad", "rest_time_err_s"}, "analytic", out);
  if (!impact_backends.empty() && set.tunnel > 0)
    tally("explore/tunnel",
          run.map(static_cast<size_t>(set.tunnel),
                  [&](size_t i) {
                    return encode(evaluate_tunnel_sample(make_tunnel_sample(set.seed, i),
                                                         impact_backends, table, cache));
                  }),
          {"velocity_err_ke"}, "analytic", out);
  return out;
}

}  // namespace rbx
