// `rbx explore`'s campaign (comparisons/eval/explore.h draws and judges one sample): every
// sample of a seed against its truth, the disagreements grouped by signature, each group shrunk
// to a scene, and explore.json's content.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_summary.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/eval/parallel.h"

namespace rbx {

/// What a campaign runs.
struct ExploreSettings {
  std::string kind = "contact";  // contact | impact | landing | slide | tunnel
  uint64_t seed = 1;             // sample k of seed s depends on (s, k) only
  long count = 20000;            // samples
  std::string backends;          // --backends LIST ("" or "all": every subject backend)
  int shrink_budget = 400;       // predicate evaluations per group (impact <= 120, landing <= 60)
  /// Contact kind: the shape classes kept, as pairs in either order ("box-box", "box-hull";
  /// classes box, hull, sliver); empty: every pair. A drawn sample of another pair is left out
  /// (counted, not redrawn), so that sample k of seed s stays the same sample.
  std::vector<std::string> shapes;
};

/// The pair names --shapes takes, and InputError naming the first it does not.
void check_shape_pairs(const std::vector<std::string>& pairs, const std::string& kind);

/// A campaign's outcome, on rank 0 (other ranks get timings only).
struct ExploreCampaign {
  Json result;                                              // explore.json
  ExploreSummary summary;                                   // explore.md's part of it, typed
  std::vector<std::pair<std::string, std::string>> scenes;  // shrunk scenes: file, text
  long groups = 0;                                          // disagreement groups
  long reproduced = 0;        // shrunk scenes on which the harness shows the disagreement
  long invalid = 0;           // samples that could not be made
  std::string first_invalid;  // the first one's reason
  double sampling_s = 0.0, shrinking_s = 0.0;
};

/// Runs the campaign over the ranks and threads of `par` (InputError on bad backend names).
ExploreCampaign run_explore(const ExploreSettings& set, const ParallelRun& par);

/// `rbx explore --bench`: the sampling alone, contact hulls under 100 points.
struct ExploreThroughput {
  std::vector<std::string> backends;  // run beside exact
  long done = 0, left_out = 0;        // samples timed; samples with a hull of 100+ points
  double seconds = 0.0;
};
ExploreThroughput explore_throughput(const ExploreSettings& set, const ParallelRun& par);

/// The regressions of explore.json `now` against the stored one at `path` (same seed, count and
/// kind, else InputError): one line per rate, error percentile or group rate that rose ("WORSE
/// ...") and per backend not in the baseline; `worse` counts the WORSE lines.
std::vector<std::string> explore_regressions(const Json& now, const std::string& path, int& worse);

/// Nearest-rank percentile of sorted values (p in [0, 100]); 0 for none.
double nearest_rank_percentile(const std::vector<double>& sorted, double p);

}  // namespace rbx
