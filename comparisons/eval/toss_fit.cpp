// Fitting one backend's contact parameters to measured tosses (tosses.h, fit_backend): e and mu
// by a grid and Nelder-Mead, then its contact softness, then e and mu again at that softness.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <functional>
#include <limits>

#include "comparisons/eval/json_io.h"
#include "comparisons/eval/tosses.h"
#include "engine/format.h"

namespace rbx {
namespace {

// Box of the search: e in [0, 1]; mu in [0, 1.5] (no tabletop pair of materials is above).
constexpr double kMaxFriction = 1.5;
constexpr double kRestitutionStep = 0.25, kFrictionStep = 0.3;  // grid spacing
constexpr int kMaxSimplexEvaluations = 30;

Eigen::Vector2d clamp_to_box(Eigen::Vector2d x) {
  x[0] = std::clamp(x[0], 0.0, 1.0);
  x[1] = std::clamp(x[1], 0.0, kMaxFriction);
  return x;
}

// Nelder-Mead (standard coefficients 1, 2, 1/2, 1/2) from `best` (its value `best_f`), a simplex
// of half a grid spacing, points clamped to the box, at most kMaxSimplexEvaluations calls of f.
// Converged when the simplex is below 0.005 in both parameters (far below what the tosses'
// spread can tell apart) or its values agree to 1e-4 cube widths. Returns the best point seen.
std::pair<Eigen::Vector2d, double> nelder_mead(
    const std::function<double(const Eigen::Vector2d&)>& f, const Eigen::Vector2d& best,
    double best_f) {
  std::array<Eigen::Vector2d, 3> x = {best,
                                      clamp_to_box(best + Eigen::Vector2d(kRestitutionStep / 2, 0)),
                                      clamp_to_box(best + Eigen::Vector2d(0, kFrictionStep / 2))};
  if (x[1] == best) x[1] = clamp_to_box(best - Eigen::Vector2d(kRestitutionStep / 2, 0));
  if (x[2] == best) x[2] = clamp_to_box(best - Eigen::Vector2d(0, kFrictionStep / 2));
  std::array<double, 3> fx = {best_f, f(x[1]), f(x[2])};
  int used = 2;
  while (used < kMaxSimplexEvaluations) {
    // Order: x[0] best, x[2] worst.
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b)
        if (fx[b] < fx[a]) std::swap(fx[a], fx[b]), std::swap(x[a], x[b]);
    const Eigen::Vector2d size = (x[1] - x[0]).cwiseAbs().cwiseMax((x[2] - x[0]).cwiseAbs());
    if ((size[0] < 5e-3 && size[1] < 5e-3) || fx[2] - fx[0] < 1e-4) break;
    const Eigen::Vector2d c = 0.5 * (x[0] + x[1]);
    const Eigen::Vector2d r = clamp_to_box(c + (c - x[2]));
    const double fr = f(r);
    ++used;
    if (fr < fx[0]) {
      const Eigen::Vector2d e = clamp_to_box(c + 2.0 * (c - x[2]));
      const double fe = f(e);
      ++used;
      if (fe < fr)
        x[2] = e, fx[2] = fe;
      else
        x[2] = r, fx[2] = fr;
    } else if (fr < fx[1]) {
      x[2] = r, fx[2] = fr;
    } else {
      const Eigen::Vector2d k = clamp_to_box(c + 0.5 * (x[2] - c));
      const double fk = f(k);
      ++used;
      if (fk < fx[2]) {
        x[2] = k, fx[2] = fk;
      } else {
        for (int i = 1; i < 3; ++i) {
          x[i] = clamp_to_box(x[0] + 0.5 * (x[i] - x[0]));
          fx[i] = f(x[i]);
          ++used;
        }
      }
    }
  }
  const size_t i = static_cast<size_t>(std::min_element(fx.begin(), fx.end()) - fx.begin());
  return {x[i], fx[i]};
}

}  // namespace

FitResult fit_backend(const Backend& backend, const std::vector<Toss>& tosses,
                      const CubeTossModel& model,
                      const std::function<void(const std::string&)>& progress) {
  Stopwatch clock;
  FitResult fit;
  auto evaluate = [&](const ContactParams& p, const std::string& what) {
    ++fit.evaluations;
    const double v = fit_objective(backend, tosses, p, model);
    if (progress)
      progress(backend.name + ": " + what + " -> " + fmt_num(v, 5) + " (" +
               fmt_num(clock.seconds(), 3) + " s)");
    return v;
  };
  // e and mu at the softness in `soft` (empty: the backend's own).
  auto over_e_mu = [&](const std::vector<std::pair<std::string, double>>& soft) {
    return [&, soft](const Eigen::Vector2d& x) {
      return evaluate({x[0], x[1], soft},
                      "e = " + fmt_num(x[0], 4) + ", mu = " + fmt_num(x[1], 4) +
                          (soft.empty() ? "" : " at " + soft_text({0, 0, soft})));
    };
  };
  // Coarse grid: the error surface has plateaus (e.g. any friction that stops sliding), so a
  // local method started from a guess could stop on one; the grid picks the basin.
  const auto f = over_e_mu({});
  Eigen::Vector2d best(0, 0);
  double best_f = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 5; ++j) {
      const Eigen::Vector2d x(i * kRestitutionStep, j * kFrictionStep);
      const double v = f(x);
      if (v < best_f) best_f = v, best = x;
    }
  const auto [x, fx] = nelder_mead(f, best, best_f);
  fit.params = {x[0], x[1], {}};
  fit.objective = fx;
  fit.stages.emplace_back("e, mu", fit.objective);
  if (backend.soft.parameters.empty()) {
    fit.seconds = clock.seconds();
    return fit;
  }
  // The contact softness at the fitted e and mu: each parameter over its grid in turn, the others
  // at their best so far (the backend's own values first). Every value's objective is kept, the
  // rejected ones beside the chosen.
  bool moved = false;
  for (const SoftParameter& sp : backend.soft.parameters) {
    ContactParams trial = fit.params;
    trial.soft.emplace_back(sp.name, sp.value);
    fit.soft_scan.push_back({sp.name, sp.value, fit.objective});
    for (const double g : sp.grid) {
      if (g == sp.value) continue;  // the backend's own value: already the objective's
      trial.soft.back().second = g;
      const double v = evaluate(trial, sp.name + " = " + fmt_num(g, 6));
      fit.soft_scan.push_back({sp.name, g, v});
      if (v < fit.objective) {
        fit.objective = v;
        fit.params = trial;
        moved = true;
      }
    }
    if (fit.params.soft.size() < trial.soft.size()) fit.params.soft.push_back({sp.name, sp.value});
  }
  fit.stages.emplace_back("softness", fit.objective);
  // e and mu again at the chosen softness (a softer or stiffer contact dissipates differently, so
  // the restitution that matched at the backend's own softness need not match now): one more
  // Nelder-Mead from the fitted point. At the backend's own softness the first fit already is
  // this search's answer.
  if (moved) {
    const auto [x2, fx2] =
        nelder_mead(over_e_mu(fit.params.soft),
                    Eigen::Vector2d(fit.params.restitution, fit.params.friction), fit.objective);
    if (fx2 < fit.objective) {
      fit.params.restitution = x2[0];
      fit.params.friction = x2[1];
      fit.objective = fx2;
    }
    fit.stages.emplace_back("e, mu at the softness", fit.objective);
  }
  fit.seconds = clock.seconds();
  return fit;
}

}  // namespace rbx
