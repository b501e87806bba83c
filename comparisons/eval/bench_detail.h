// The bench's cases as its two files share them: what a group's timings gave, a family's groups,
// and the query families' builders (comparisons/eval/bench_query_cases.cpp). Internal to rbx
// bench; comparisons/eval/bench_cases.h is the interface.
#pragma once

#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "comparisons/eval/bench_cases.h"

namespace rbx::bench_detail {

// What the groups' timings gave, per case name.

struct CaseTimes {
  std::map<std::string, Rounds> rounds;  // per call, seconds
  std::map<std::string, double> cold_s;  // the warm-up pass, timed alone
  std::map<std::string, std::string> errors;
  // A case's time in a row's unit (`scale` per second of a call), or an error.
  BenchTime time(const std::string& name, double scale) const {
    const auto it = rounds.find(name);
    if (it == rounds.end() || it->second.per_call_s.empty()) return {};
    std::vector<double> v;
    for (double t : it->second.per_call_s) v.push_back(t * scale);
    BenchTime out = bench_time(v);
    out.calls = it->second.per_round * out.rounds;
    if (cold_s.count(name)) out.cold = cold_s.at(name) * scale;
    return out;
  }
};

// A family's groups, and how it turns their timings into its rows once they have run.
struct CaseSet {
  std::vector<BenchGroup> groups;
  std::function<void(const CaseTimes&, BenchResults&)> collect;
};

/// Narrow phase: every backend of narrow_backends() on every shape size and pose kind.
CaseSet narrowphase_cases(const BenchPlan& plan, std::mt19937_64& rng);
/// Distance: every query of distance_backends() on every shape size, 1 % and 20 % apart.
CaseSet distance_cases(const BenchPlan& plan, std::mt19937_64& rng);
/// Time of impact: every query of toi_backends() on the distance queries' poses, B moving onto A.
CaseSet toi_cases(const BenchPlan& plan, std::mt19937_64& rng);

}  // namespace rbx::bench_detail
