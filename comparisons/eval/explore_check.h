// The fixed random samples `rbx check` runs beside the scene library: a change that breaks
// random poses, impacts at a random phase, landings or slides with friction or fast projectiles,
// which no scene of the library shows, moves these metrics and fails the check.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/parallel.h"
#include "comparisons/eval/result_cache.h"
#include "reference/backend.h"

namespace rbx {

/// Which samples: explore's own families (contact, distance, impact, landing, slide and tunnel
/// kinds), from one seed.
struct ExploreCheckSet {
  uint64_t seed = 1;
  int contact = 2000;   // contact-kind samples
  int distance = 1000;  // distance-kind samples
  int impact = 300;     // impact-kind samples
  int landing = 300;    // landing-kind samples
  int slide = 200;      // slide-kind samples
  int tunnel = 200;     // tunnel-kind samples
  int toi = 300;        // toi-kind samples
};

/// One metric of the sample set, under a pseudo-scene name ("explore/contact",
/// "explore/distance", "explore/impact", "explore/landing", "explore/slide", "explore/tunnel") so
/// that it takes its place beside the scenes' metrics.
struct ExploreCheckMetric {
  std::string scene;
  Metric metric;
};

/// One backend's row of a query's section in the report (the distance and time-of-impact
/// kinds): what it got wrong, sample by sample, and how its errors spread.
struct QueryFamilyRow {
  std::string backend;
  long samples = 0, disagreements = 0;
  long measured = 0;  // samples with an error measured (distance: both apart; toi: both touch)
  /// Toi kind: measured samples right although their time is more than kToiDisagree off, the
  /// pair within kToiTouchBand of touching at it (a grazing touch, toi_query.h).
  long grazing = 0;
  /// One kind of disagreement (docs/explore.md's names): how many samples, the first of them,
  /// and for the toi kind's `early` and `late` the median and largest |separation| of the pair
  /// at the row's time (m): how far short it stopped, or how deep it went.
  struct Kind {
    std::string name;
    long count = 0;
    uint64_t first = 0;
    double separation_p50 = 0.0, separation_max = 0.0;
  };
  std::vector<Kind> kinds;        // the most frequent first
  std::vector<double> quantiles;  // the main error at 0, 5, ..., 100 % of the measured samples
  double p50 = 0.0, p90 = 0.0, p99 = 0.0;       // the main error
  double witness_p50 = 0.0, witness_p90 = 0.0;  // distance kind: witness_err_rel
  /// Run time per query (s) on the family's first kQueryTimedSamples samples, each the median
  /// over interleaved rounds (timing.h): the median over those samples and its 25-75 % range,
  /// which spans their sizes (4 to 2,000 points), not noise. timed = 0: not timed.
  double time_s = 0.0, time_q25_s = 0.0, time_q75_s = 0.0;
  int timed = 0;
};

/// How many of a query family's samples its rows are timed on (QueryFamilyRow::time_s).
constexpr int kQueryTimedSamples = 40;

/// A query's section: its backends ranked by disagreement rate, then median error, then name.
struct QueryFamily {
  std::string scene;  // "explore/distance" | "explore/toi"
  std::string error;  // the main error: "distance_err_rel" | "time_err"
  long count = 0;     // samples drawn
  std::vector<QueryFamilyRow> rows;
};

/// A query's section from its samples' encoded outcomes (explore.h's encode), `error` its main
/// error ("distance_err_rel" or "time_err").
QueryFamily query_family(const std::string& scene, const std::string& error,
                         const std::vector<std::string>& encoded);

/// Per backend: the disagreement rate and the median and 90th percentile of its errors (contact:
/// normal_err_deg, depth_err_rel; distance, for the contact backends with a distance query:
/// distance_err_rel, witness_err_rel; impact: velocity_err_ke; landing: position_err_m, turn_rad;
/// slide: those and rest_time_err_s; tunnel: velocity_err_ke), over the samples, exactly as
/// `rbx explore` classifies them. Impacts, landings, slides and tunnels run the
/// dynamics backends. Backends are looked up in `table` (null: the registry). The samples
/// run on `run`'s ranks and threads (null: a run of its own); every rank must call it, the
/// metrics come back on rank 0. `cache`, when given, serves and keeps the libraries' answers
/// (result_cache.h): an engine edit reruns only the engines' samples. `queries`, when given,
/// gets the distance and toi kinds' sections (on rank 0).
std::vector<ExploreCheckMetric> explore_check_metrics(
    const std::vector<std::string>& contact_backends,
    const std::vector<std::string>& impact_backends, const ExploreCheckSet& set,
    const std::vector<Backend>* table = nullptr, const ParallelRun* run = nullptr,
    const ResultCache* cache = nullptr, std::vector<QueryFamily>* queries = nullptr);

}  // namespace rbx
