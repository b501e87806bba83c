// Solver budgets: what each dynamics backend's error does along its iteration budget at the
// scene's step (the harness's "budget" points of error against run time, Backend::budget), summed
// up per backend and scene family: the smallest budget that reaches the backend's own converged
// error.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/measures.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// Two errors of one backend on one scene are the same to this fraction of the converged one:
/// two digits, the resolution at which the report compares errors.
constexpr double kBudgetConvergedRel = 0.01;
/// Errors this small are round-off (the report's floor): any budget that reaches one is
/// converged.
constexpr double kBudgetRoundoff = 1e-13;

/// One backend's budget points on one scene (kind "budget"): `be` at the scene's step at each
/// value of be.budget, the error of each run's final states from `error_of`, against `against`;
/// `main` (the configured run) stands for the configured value. A run that fails at some budget
/// gives no point and is named in `skipped` (when given).
std::vector<ErrorRuntimePoint> budget_points(
    const Backend& be, const Scene& scene, const DynRun& main, const ResultCache& cache,
    const std::vector<RigidBody>& bodies,
    const std::function<double(const std::vector<BodyFinal>&)>& error_of,
    const std::string& against, std::vector<std::string>* skipped = nullptr);

/// Along one budget study, (budget, error) in any order: the smallest budget from which every
/// larger budget's error is within kBudgetConvergedRel of the error at the largest budget (the
/// backend's own converged error), or within round-off of it. 0 for an empty study.
int converged_budget(std::vector<std::pair<int, double>> points);

/// One backend on one scene family.
struct BudgetRow {
  std::string backend, family;
  int scenes = 0;        // scenes with a budget study
  int every_scene = 0;   // the smallest budget converged on every scene (the largest of theirs)
  int median_scene = 0;  // the median scene's (the lower middle of an even count)
  double default_error = -1.0;   // median over scenes: the error at the library's default
                                 // (-1: the library has none, Backend::budget)
  double converged_error = 0.0;  // median over scenes: the error at the largest budget
};

/// Every backend and family with budget points in `evs`, in the order first met.
std::vector<BudgetRow> budget_rows(const std::vector<SceneEvaluation>& evs);

}  // namespace rbx
