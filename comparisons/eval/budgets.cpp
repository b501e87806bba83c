#include "comparisons/eval/budgets.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <utility>

#include "comparisons/eval/metrics.h"
#include "reference/backend.h"

namespace rbx {

std::vector<ErrorRuntimePoint> budget_points(
    const Backend& be, const Scene& scene, const DynRun& main, const ResultCache& cache,
    const std::vector<RigidBody>& bodies,
    const std::function<double(const std::vector<BodyFinal>&)>& error_of,
    const std::string& against, std::vector<std::string>* skipped) {
  std::vector<ErrorRuntimePoint> points;
  for (int budget : be.budget.values) {
    std::optional<DynRun> other;
    if (budget != be.budget.configured)
      other = run_dynamics(be, scene, scene.sim.dt, 0, cache, bodies, budget);
    const DynRun& r = other ? *other : main;
    if (r.result.status != Status::Ok) {
      if (skipped)
        skipped->push_back(be.name + " at solver budget " + std::to_string(budget) + ": " +
                           r.result.message);
      continue;
    }
    points.push_back({be.name, "budget", scene.sim.dt, Timing::once(r.runtime_s),
                      error_of(r.result.finals), against, budget});
  }
  return points;
}

int converged_budget(std::vector<std::pair<int, double>> points) {
  if (points.empty()) return 0;
  std::sort(points.begin(), points.end());
  const double converged = points.back().second;
  const auto same = [&](double e) {
    return std::abs(e - converged) <= kBudgetConvergedRel * std::abs(converged) ||
           (e <= kBudgetRoundoff && converged <= kBudgetRoundoff);
  };
  // Walk down from the largest budget while the error stays the converged one.
  int smallest = points.back().first;
  for (auto it = points.rbegin(); it != points.rend() && same(it->second); ++it)
    smallest = it->first;
  return smallest;
}

std::vector<BudgetRow> budget_rows(const std::vector<SceneEvaluation>& evs) {
  struct Acc {
    std::vector<int> converged;
    std::vector<double> at_default, at_top;
  };
  std::vector<std::pair<std::string, std::string>> order;  // (backend, family) as first met
  std::map<std::pair<std::string, std::string>, Acc> acc;
  for (const SceneEvaluation& ev : evs) {
    std::map<std::string, std::vector<std::pair<int, double>>> per_backend;
    std::vector<std::string> met;
    for (const ErrorRuntimePoint& p : ev.error_vs_runtime) {
      if (p.kind != "budget") continue;
      if (!per_backend.count(p.backend)) met.push_back(p.backend);
      per_backend[p.backend].emplace_back(p.budget, p.error);
    }
    for (const std::string& b : met) {
      const auto key = std::make_pair(b, ev.family);
      if (!acc.count(key)) order.push_back(key);
      std::vector<std::pair<int, double>>& pts = per_backend[b];
      Acc& a = acc[key];
      a.converged.push_back(converged_budget(pts));
      a.at_top.push_back(std::max_element(pts.begin(), pts.end())->second);  // largest budget
      const Backend* be = find_backend(b);
      for (const auto& [budget, error] : pts)
        if (be && budget == be->budget.library_default) a.at_default.push_back(error);
    }
  }
  // Budgets: the lower middle of an even count (a budget of the study); errors: the median.
  const auto lower_middle = [](std::vector<int> v) {
    std::sort(v.begin(), v.end());
    return v[(v.size() - 1) / 2];
  };
  std::vector<BudgetRow> rows;
  for (const auto& key : order) {
    const Acc& a = acc[key];
    BudgetRow r;
    r.backend = key.first;
    r.family = key.second;
    r.scenes = static_cast<int>(a.converged.size());
    r.every_scene = *std::max_element(a.converged.begin(), a.converged.end());
    r.median_scene = lower_middle(a.converged);
    if (!a.at_default.empty()) r.default_error = median_of(a.at_default);
    r.converged_error = median_of(a.at_top);
    rows.push_back(r);
  }
  return rows;
}

}  // namespace rbx
