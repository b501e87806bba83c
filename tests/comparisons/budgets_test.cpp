// Solver budgets: the smallest budget that reaches a backend's own converged error, the rows the
// report shows, and the harness's study along each backend's budget.
#include "comparisons/eval/budgets.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "comparisons/scene/scene_file.h"
#include "reference/backend.h"

namespace rbx {
namespace {

TEST(ConvergedBudget, IsWhereTheErrorStopsMovingForGood) {
  // 0.0101 is within 1 % of the converged 0.0100; 0.1 is not.
  EXPECT_EQ(converged_budget({{1, 0.5}, {3, 0.1}, {10, 0.0101}, {30, 0.01}, {100, 0.01}}), 10);
  // An error that touches the converged one and leaves it again: converged only at the top.
  EXPECT_EQ(converged_budget({{1, 0.02}, {3, 0.01}, {10, 0.05}, {100, 0.01}}), 100);
  // The order of the points does not matter.
  EXPECT_EQ(converged_budget({{100, 2.0}, {1, 2.0}, {10, 2.0}}), 1);
  // Two round-off errors are the same error, however far apart in ratio.
  EXPECT_EQ(converged_budget({{1, 1e-3}, {5, 3e-14}, {20, 1e-15}}), 5);
  EXPECT_EQ(converged_budget({}), 0);
}

// One scene's evaluation holding `bullet`'s budget points (and a step point, which the rows
// ignore).
SceneEvaluation budget_scene(const std::string& family,
                             const std::vector<std::pair<int, double>>& points) {
  SceneEvaluation ev;
  ev.family = family;
  ev.error_vs_runtime.push_back({"bullet", "dynamics", 0.02, Timing::once(1e-3), 9.0, "analytic"});
  for (const auto& [budget, error] : points)
    ev.error_vs_runtime.push_back(
        {"bullet", "budget", 0.01, Timing::once(1e-3), error, "analytic", budget});
  return ev;
}

TEST(BudgetRows, GiveTheWorstAndTheMedianSceneOfEachFamily) {
  ASSERT_EQ(find_backend("bullet")->budget.library_default, 10);
  const std::vector<SceneEvaluation> evs = {
      budget_scene("analytic", {{1, 0.1}, {3, 0.01}, {10, 0.01}, {30, 0.01}, {100, 0.01}}),
      budget_scene("analytic", {{1, 0.3}, {3, 0.2}, {10, 0.2}, {30, 0.1}, {100, 0.1}}),
      budget_scene("analytic", {{1, 1.0}, {3, 1.0}, {10, 1.0}, {30, 1.0}, {100, 1.0}}),
      budget_scene("friction", {{1, 4.0}, {3, 2.0}, {10, 1.0}, {30, 1.0}, {100, 1.0}}),
  };
  const std::vector<BudgetRow> rows = budget_rows(evs);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].family, "analytic");
  EXPECT_EQ(rows[0].backend, "bullet");
  EXPECT_EQ(rows[0].scenes, 3);
  EXPECT_EQ(rows[0].every_scene, 30);  // the second scene needs 30
  EXPECT_EQ(rows[0].median_scene, 3);  // of 1, 3 and 30
  // At the default (10): 0.01, 0.2 and 1.0; at the top: 0.01, 0.1 and 1.0.
  EXPECT_DOUBLE_EQ(rows[0].default_error, 0.2);
  EXPECT_DOUBLE_EQ(rows[0].converged_error, 0.1);
  EXPECT_EQ(rows[1].family, "friction");
  EXPECT_EQ(rows[1].every_scene, 10);
}

TEST(BudgetStudy, RunsEveryBudgetOfEveryBackendAtTheScenesStep) {
  // A head-on impact of two cubes, face on face: one four-point manifold, a closed form.
  const Scene scene = load_scene(RBX_SOURCE_DIR "/scenes/analytic/headon_e05.toml");
  HarnessOptions opt;
  opt.backends = "bullet,ode,custom,custom-seed";
  opt.phases = false;
  opt.timing_budget_s = 0.0;  // the verdicts only: no run is timed again
  const SceneEvaluation ev = evaluate_scene(scene, opt);
  std::map<std::string, std::vector<std::pair<int, double>>> points;
  for (const ErrorRuntimePoint& p : ev.error_vs_runtime)
    if (p.kind == "budget") {
      EXPECT_DOUBLE_EQ(p.dt, scene.sim.dt) << p.backend;
      EXPECT_EQ(p.against, "analytic") << p.backend;
      points[p.backend].emplace_back(p.budget, p.error);
    }
  for (const char* name : {"bullet", "ode", "custom"}) {
    std::vector<int> studied;
    for (const auto& pt : points[name]) studied.push_back(pt.first);
    EXPECT_EQ(studied, find_backend(name)->budget.values) << name;
  }
  EXPECT_EQ(points.count("custom-seed"), 0u);  // one impulse in closed form: no budget
  // The JSON names each budget point's budget.
  int in_json = 0;
  for (const Json& p : ev.json["error_vs_runtime"])
    if (p["kind"] == "budget") in_json += p.contains("budget") ? 1 : 0;
  EXPECT_EQ(in_json, static_cast<int>(points["bullet"].size() + points["ode"].size() +
                                      points["custom"].size()));
  // The custom engine settles a four-point island by active sets, which no iteration budget limits.
  EXPECT_EQ(converged_budget(points["custom"]), 1);
  // Bullet's sequential impulses over the four points converge along the budget: far off after
  // one iteration, round-off at the fair world's 100 (so the budget reaches its solver).
  const auto& bullet = points["bullet"];
  EXPECT_GT(bullet.front().second, 1e-3);
  EXPECT_LE(bullet.back().second, kBudgetRoundoff);
  for (size_t i = 1; i < bullet.size(); ++i)
    EXPECT_LE(bullet[i].second, bullet[i - 1].second) << "budget " << bullet[i].first;
  // ODE's quick step (successive over-relaxation) improves along its iterations too.
  EXPECT_GT(points["ode"].front().second, 10 * points["ode"].back().second);
}

TEST(SolverBudgets, AreStudiedOverFourValuesOrMoreWithTheLibraryDefault) {
  int with_budget = 0;
  for (const Backend& b : backends()) {
    if (b.budget.values.empty()) continue;
    ++with_budget;
    EXPECT_TRUE(b.dynamics) << b.name;
    EXPECT_GE(b.budget.values.size(), 4u) << b.name;
    EXPECT_TRUE(std::is_sorted(b.budget.values.begin(), b.budget.values.end())) << b.name;
    EXPECT_GT(b.budget.values.front(), 0) << b.name;
    // The library's default is studied, unless it has none (it solves to convergence).
    if (b.budget.library_default != 0) {
      EXPECT_NE(std::find(b.budget.values.begin(), b.budget.values.end(), b.budget.library_default),
                b.budget.values.end())
          << b.name;
    }
    EXPECT_FALSE(b.budget.what.empty()) << b.name;
  }
  // Bullet, MuJoCo, ODE and DART (each on both shape paths) and the custom engine.
  EXPECT_EQ(with_budget, 9);
}

}  // namespace
}  // namespace rbx
