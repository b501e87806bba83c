// What explore.md shows of a campaign, typed: read once from explore.json (the campaign's own,
// or one stored earlier), so that the page renders fields, not keys.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"

namespace rbx {

/// One error metric's distribution over a backend's samples (nearest-rank percentiles).
struct ExplorePercentiles {
  double p50 = 0.0, p90 = 0.0, p99 = 0.0, max = 0.0;
};

/// One disagreement group: its signature, how often, and the scene it was shrunk to.
struct ExploreGroup {
  std::string signature;
  long count = 0;
  double rate = 0.0;
  std::optional<std::string> scene;                // none where the shrink failed
  std::optional<int> points_before, points_after;  // a hull's points, where they changed
  bool reproduced = false;                         // the harness shows it on the shrunk scene
};

/// The samples whose first contact falls in one quarter of its step, and how many disagree.
struct ExplorePhaseQuarter {
  long samples = 0;
  double rate = 0.0;
};

/// One backend (or, for the toi kind, one variant) over the campaign.
struct ExploreBackendSummary {
  std::string name;
  long samples = 0, disagreements = 0;
  double rate = 0.0;
  std::optional<long> coverage_misses;                // the contact kind's
  std::map<std::string, ExplorePercentiles> errors;   // by metric name (metrics_of)
  std::vector<ExplorePhaseQuarter> by_phase_quarter;  // impact, landing, tunnel: four
  std::vector<ExploreGroup> groups;                   // largest first

  /// The distribution of `metric`; InputError naming it when the campaign did not record it.
  const ExplorePercentiles& error(const std::string& metric) const;
};

/// A campaign as explore.md shows it: what was drawn, and each backend's tallies.
struct ExploreSummary {
  std::string kind;  // contact | distance | impact | landing | slide | tunnel | toi
  uint64_t seed = 0;
  long count = 0;
  std::vector<ExploreBackendSummary> backends;  // in explore.json's order
};

/// The summary of explore.json `j` (InputError on a document that lacks a field it needs).
ExploreSummary read_explore_summary(const Json& j);

}  // namespace rbx
