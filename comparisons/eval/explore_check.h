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

/// Per backend: the disagreement rate and the median and 90th percentile of its errors (contact:
/// normal_err_deg, depth_err_rel; distance, for the contact backends with a distance query:
/// distance_err_rel, witness_err_rel; impact: velocity_err_ke; landing: position_err_m, turn_rad;
/// slide: those and rest_time_err_s; tunnel: velocity_err_ke), over the samples, exactly as
/// `rbx explore` classifies them. Impacts, landings, slides and tunnels run the
/// dynamics backends. Backends are looked up in `table` (null: the registry). The samples
/// run on `run`'s ranks and threads (null: a run of its own); every rank must call it, the
/// metrics come back on rank 0. `cache`, when given, serves and keeps the libraries' answers
/// (result_cache.h): an engine edit reruns only the engines' samples.
std::vector<ExploreCheckMetric> explore_check_metrics(
    const std::vector<std::string>& contact_backends,
    const std::vector<std::string>& impact_backends, const ExploreCheckSet& set,
    const std::vector<Backend>* table = nullptr, const ParallelRun* run = nullptr,
    const ResultCache* cache = nullptr);

}  // namespace rbx
