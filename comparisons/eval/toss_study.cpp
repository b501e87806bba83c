// The tosses study: which backends run, both parameter sets over every toss, the study's JSON,
// the ranking and the parameter file (`rbx tosses` and the report's "Real impacts" section).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/parallel.h"
#include "comparisons/eval/select_backends.h"
#include "comparisons/eval/tosses.h"
#include "comparisons/scene/repo_path.h"
#include "comparisons/scene/scene_file.h"
#include "engine/format.h"

namespace fs = std::filesystem;

namespace rbx {

namespace {

// The best, median and worst toss of `best` (label, toss id); none when it has no tosses.
std::vector<std::pair<std::string, long>> toss_picks(const BackendTosses& best) {
  if (best.tosses.empty()) return {};
  std::vector<TossErrors> sorted = best.tosses;
  std::stable_sort(sorted.begin(), sorted.end(), [](const TossErrors& a, const TossErrors& b) {
    return a.position < b.position;
  });
  return {{"best", sorted.front().toss_id},
          {"median", sorted[(sorted.size() - 1) / 2].toss_id},
          {"worst", sorted.back().toss_id}};
}

Json model_json(const CubeTossModel& m) {
  return {{"cube_width_m", 2.0 * m.half_width},
          {"mass_kg", m.mass},
          {"gravity_mps2", m.gravity},
          {"sample_rate_hz", m.sample_rate},
          {"substeps", m.substeps},
          {"dt_s", 1.0 / (m.sample_rate * m.substeps)},
          {"floor", "static box " + fmt_num(m.floor_size, 3) + " x " + fmt_num(m.floor_size, 3) +
                        " x " + fmt_num(m.floor_thickness, 3) + " m, top face z = 0"}};
}

}  // namespace

ContactParams stored_params(const std::vector<std::pair<std::string, ContactParams>>& stored,
                            const std::string& name, std::string* source) {
  for (const auto& [n, p] : stored)
    if (n == name) {
      if (source) *source = "fitted";
      return p;
    }
  if (source) *source = "published (none stored)";
  return kPublishedParams;
}

std::string toss_test_split(const std::string& dir) {
  const fs::path d(dir);
  return (fs::exists(d / "test.csv.gz") ? d / "test.csv.gz" : d / "test.csv").string();
}

std::vector<const Backend*> select_toss_backends(const std::string& list) {
  std::vector<const Backend*> out;
  if (list.empty() || list == "all") {
    for (const Backend& b : backends())
      if (b.dynamics) out.push_back(&b);
    return out;
  }
  const std::vector<std::string> names = parse_backend_list(list);
  for (const Backend& b : backends())
    if (std::find(names.begin(), names.end(), b.name) != names.end()) out.push_back(&b);
  if (out.empty()) throw InputError("--backends: no backend named");
  return out;
}

std::vector<EnergyGain> energy_gains(const std::vector<Toss>& tosses, const CubeTossModel& model) {
  std::vector<EnergyGain> out;
  const double h = model.half_width;
  for (const Toss& t : tosses) {
    // Energy and flight at each sample; flights as [begin, end) runs of samples.
    std::vector<double> energy;
    std::vector<std::pair<size_t, size_t>> flights;
    for (size_t k = 0; k < t.samples.size(); ++k) {
      const TossSample& s = t.samples[k];
      energy.push_back(0.5 * model.mass * s.velocity.squaredNorm() +
                       0.5 * model.inertia * s.angular_velocity.squaredNorm() +
                       model.mass * model.gravity * s.position.z());
      // The lowest corner: the centre's height less the half widths along each rotated axis.
      const Mat3 r = s.orientation.toRotationMatrix();
      const double lowest = s.position.z() - h * r.row(2).cwiseAbs().sum();
      const bool flying = lowest > kFlightClearance;
      if (flying && (flights.empty() || flights.back().second != k)) flights.push_back({k, k});
      if (flying) flights.back().second = k + 1;
    }
    EnergyGain g;
    g.toss_id = t.id;
    g.noise = 0.01;
    for (const auto& [b, e] : flights) {
      const auto [lo, hi] = std::minmax_element(energy.begin() + b, energy.begin() + e);
      g.noise = std::max(g.noise, (*hi - *lo) / std::abs(*hi));
    }
    for (size_t f = 1; f < flights.size(); ++f) {
      const double before = energy[flights[f - 1].second - 1];
      const double after =
          *std::max_element(energy.begin() + flights[f].first, energy.begin() + flights[f].second);
      g.ratio = std::max(g.ratio, after / before);
    }
    if (g.ratio > 1.0 + g.noise) out.push_back(g);
  }
  return out;
}

std::vector<Toss> without_energy_gains(const std::vector<Toss>& tosses,
                                       const std::vector<EnergyGain>& flagged) {
  std::vector<Toss> kept;
  for (const Toss& t : tosses)
    if (std::none_of(flagged.begin(), flagged.end(),
                     [&](const EnergyGain& g) { return g.toss_id == t.id; }))
      kept.push_back(t);
  return kept;
}

std::string energy_gains_list(const std::vector<EnergyGain>& flagged) {
  std::string s;
  for (const EnergyGain& g : flagged)
    s += (s.empty() ? " (toss " : "; toss ") + std::to_string(g.toss_id) + ": energy x" +
         fmt_num(g.ratio, 3) + ", noise " + fmt_num(g.noise, 2);
  return s.empty() ? s : s + ")";
}

Json energy_gains_json(const std::vector<EnergyGain>& flagged, size_t scored) {
  Json j;
  j["rule"] =
      "left out of every fit and score: a toss whose energy (m v^2/2 + I w^2/2 + m g z, from the "
      "data's states) in a flight after a contact exceeds that at the end of the flight before "
      "it by more than the tracking noise (the largest relative swing of its energy within one "
      "flight, at least 1 %); flight: the lowest corner more than 3 mm above the floor";
  j["flagged"] = Json::array();
  for (const EnergyGain& g : flagged)
    j["flagged"].push_back({{"toss", g.toss_id}, {"ratio", g.ratio}, {"noise", g.noise}});
  j["scored"] = scored;
  return j;
}

TossEvaluation evaluate_tosses(const std::vector<const Backend*>& chosen,
                               const std::vector<Toss>& tosses,
                               const std::vector<std::pair<std::string, ContactParams>>& stored,
                               int threads) {
  // Job 2k is backend k at its stored parameters, 2k + 1 at the published ones. Each toss of a
  // job forks its supervised child (isolated_dynamics_fn), so the jobs run on several threads,
  // taken as they come free, and land in their own slots.
  const size_t jobs = 2 * chosen.size();
  std::vector<BackendTosses> done(jobs);
  run_jobs(jobs, threads, [&](size_t j) {
    const Backend& b = *chosen[j / 2];
    std::string source = "published";
    const ContactParams p = j % 2 == 0 ? stored_params(stored, b.name, &source) : kPublishedParams;
    done[j] = evaluate_backend(b, tosses, p);
    done[j].params_source = source;
  });
  TossEvaluation ev;
  for (size_t j = 0; j < jobs; ++j) (j % 2 == 0 ? ev.stored : ev.published).push_back(done[j]);
  return ev;
}

Json toss_evaluation_json(const std::string& data, const std::vector<Toss>& tosses,
                          const std::string& params_file, const TossEvaluation& ev) {
  Json j;
  j["data"] = data;
  j["tosses"] = tosses.size();
  size_t samples = 0;
  for (const Toss& t : tosses) samples += t.samples.size();
  j["samples"] = samples;
  j["model"] = model_json(CubeTossModel{});
  j["params_file"] = params_file;
  j["errors"] =
      "position: mean |p_sim - p_real| / cube width over the samples after t = 0; orientation: "
      "mean rotation angle (deg) between simulated and measured orientation; final: the same at "
      "the last (resting) sample; median, mean, p90 over tosses";
  j["backends"] = Json::object();
  for (const BackendTosses& r : ev.stored) j["backends"][r.name] = backend_tosses_json(r);
  j["published_params"]["params"] = {{"restitution", kPublishedParams.restitution},
                                     {"friction", kPublishedParams.friction}};
  j["published_params"]["backends"] = Json::object();
  for (const BackendTosses& r : ev.published)
    j["published_params"]["backends"][r.name] = backend_tosses_json(r);
  return j;
}

std::vector<size_t> toss_ranking(const std::vector<BackendTosses>& rs) {
  std::vector<size_t> order;
  for (size_t i = 0; i < rs.size(); ++i) order.push_back(i);
  auto key = [&](size_t i) {
    std::vector<double> v;
    for (const TossErrors& e : rs[i].tosses) v.push_back(e.position);
    const double m = spread_of(v).median;
    return std::isfinite(m) ? m : std::numeric_limits<double>::infinity();
  };
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
  return order;
}

std::string default_toss_params_path(const std::string& data) {
  const fs::path dir = fs::path(data).parent_path();
  return (dir.empty() ? fs::path("params.json") : dir / "params.json").string();
}

Json updated_params_json(const std::string& path, const std::string& data,
                         const std::vector<std::pair<std::string, FitResult>>& fits) {
  Json j;
  std::error_code ec;
  if (fs::exists(path, ec)) {
    read_params_file(path);  // validates
    std::ifstream in(path);
    j = Json::parse(in);
  }
  j["about"] =
      "Restitution e and Coulomb friction mu per dynamics backend, fitted on the training tosses "
      "by `rbx tosses train.csv.gz --fit` (5 x 6 grid over e in [0, 1], mu in [0, 1.5], then "
      "Nelder-Mead; objective: mean position error in cube widths); then, for a backend with a "
      "contact softness its experts tune (soft: MuJoCo's contact duration in steps and impedance, "
      "ODE's and DART's erp and cfm, Bullet's contact erp and cfm), each such parameter "
      "over its grid (soft_grid) at the fitted e and mu, the best kept (soft_scan: every value "
      "tried and its objective), and, when the softness moved from the backend's own (soft_own), "
      "e and mu fitted again at it (fit_stages: the objective after each stage). Backends not "
      "listed run at the published e = 0.125, mu = 0.18 and their own softness.";
  j["model"] = model_json(CubeTossModel{});
  Json& b = j["backends"];
  if (!b.is_object()) b = Json::object();
  for (const auto& [name, fit] : fits) {
    b[name] = {{"restitution", fit.params.restitution},
               {"friction", fit.params.friction},
               {"fit_data", fs::path(data).filename().string()},
               {"train_position_error", fit.objective},
               {"evaluations", fit.evaluations},
               {"fit_s", fit.seconds}};
    for (const auto& [p, v] : fit.params.soft) b[name]["soft"][p] = v;
    for (const auto& [stage, v] : fit.stages)
      b[name]["fit_stages"].push_back({{"stage", stage}, {"train_position_error", v}});
    for (const SoftTrial& t : fit.soft_scan)
      b[name]["soft_scan"][t.parameter].push_back({t.value, t.objective});
    if (const Backend* be = find_backend(name))
      for (const SoftParameter& p : be->soft.parameters) {
        b[name]["soft_grid"][p.name] = p.grid;
        b[name]["soft_own"][p.name] = p.value;
      }
  }
  // Registry order, so refitting one backend does not reorder the file.
  Json sorted = Json::object();
  for (const Backend& r : backends())
    if (b.contains(r.name)) sorted[r.name] = b[r.name];
  for (const auto& [name, v] : b.items())
    if (!sorted.contains(name)) sorted[name] = v;
  b = sorted;
  return j;
}

std::vector<std::string> find_toss_datasets(const std::vector<std::string>& inputs) {
  std::vector<std::string> roots = inputs;
  if (roots.empty()) roots.push_back(default_repo_path("scenes"));
  std::vector<std::string> found;
  for (const std::string& root : roots) {
    std::error_code ec;
    if (!fs::is_directory(root, ec)) continue;
    auto consider = [&](const fs::path& d) {
      if (fs::exists(d / "params.json") &&
          (fs::exists(d / "test.csv.gz") || fs::exists(d / "test.csv")))
        found.push_back(d.string());
    };
    consider(root);  // the folder itself, then every folder below it
    for (const auto& e : fs::recursive_directory_iterator(root, ec))
      if (e.is_directory()) consider(e.path());
  }
  std::sort(found.begin(), found.end());
  return found;
}

TossReportStudy run_toss_report_study(const std::string& dir, const std::string& backend_list,
                                      int threads) {
  TossReportStudy study;
  study.data = toss_test_split(dir);
  const std::vector<Toss> all = read_tosses(study.data);
  study.all_tosses = all.size();
  study.flagged = energy_gains(all);
  study.tosses = without_energy_gains(all, study.flagged);
  study.params_path = (fs::path(dir) / "params.json").string();
  const auto stored = read_params_file(study.params_path);
  // Backends without dynamics named in the report's --backends are simply not tossed.
  for (const Backend* b : select_toss_backends(backend_list))
    if (b->dynamics) study.chosen.push_back(b);
  if (study.chosen.empty()) return study;
  Stopwatch clock;
  study.ev = evaluate_tosses(study.chosen, study.tosses, stored, threads);
  study.eval_s = clock.seconds();
  study.order = toss_ranking(study.ev.stored);
  for (const auto& [label, id] : toss_picks(study.ev.stored[study.order.front()])) {
    PickedToss pick{label, id, {}};
    const Toss& t = *std::find_if(study.tosses.begin(), study.tosses.end(),
                                  [&, id = id](const Toss& x) { return x.id == id; });
    for (size_t k = 0; k < study.chosen.size(); ++k)
      pick.runs.emplace_back(
          study.chosen[k]->name,
          simulate_toss(isolated_dynamics_fn(*study.chosen[k]), t, study.ev.stored[k].params));
    study.picks.push_back(std::move(pick));
  }
  return study;
}

}  // namespace rbx
