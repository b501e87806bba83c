// `rbx tosses DATA.csv`: every dynamics backend against measured cube tosses.
#include <filesystem>
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/tosses.h"
#include "comparisons/output/tosses_report.h"
#include "comparisons/scene/scene_file.h"

namespace fs = std::filesystem;

namespace rbx {

int tosses_command(const TossesOptions& opt) {
  // Everything is read and validated before anything runs or is written.
  const std::vector<Toss> all = read_tosses(opt.data);
  // Tosses that gain energy across an impact are left out of every fit and score.
  const std::vector<EnergyGain> flagged = energy_gains(all);
  const std::vector<Toss> tosses = without_energy_gains(all, flagged);
  const std::vector<const Backend*> chosen = select_toss_backends(opt.backends);
  const std::string params_path =
      opt.params.empty() ? default_toss_params_path(opt.data) : opt.params;
  std::error_code ec;
  if (!opt.params.empty() && !opt.fit && !fs::exists(opt.params, ec))
    throw InputError(opt.params + ": no such parameter file");
  auto stored = read_params_file(params_path);

  if (opt.fit) {
    std::vector<std::pair<std::string, FitResult>> fits;
    for (const Backend* b : chosen) {
      if (!b->dynamics) continue;
      std::cerr << "fitting " << b->name << " on " << tosses.size() << " tosses\n";
      const FitResult fit = fit_backend(*b, tosses, CubeTossModel{}, [](const std::string& s) {
        std::cerr << "  " << s << "\n";
      });
      std::cerr << b->name << ": e = " << fmt_num(fit.params.restitution, 4)
                << ", mu = " << fmt_num(fit.params.friction, 4) << ", error "
                << fmt_num(fit.objective, 4) << " widths, " << fit.evaluations << " evaluations, "
                << fmt_num(fit.seconds, 4) << " s\n";
      fits.emplace_back(b->name, fit);
    }
    write_json(params_path, updated_params_json(params_path, opt.data, fits));
    stored = read_params_file(params_path);
  }

  const TossEvaluation ev = evaluate_tosses(chosen, tosses, stored);
  Json j = toss_evaluation_json(opt.data, tosses, params_path, ev);
  j["energy_gain"] = energy_gains_json(flagged, tosses.size());
  if (!opt.json.empty()) write_json(opt.json, j);
  if (opt.json != "-") {
    std::cout << opt.data << ": " << tosses.size() << " tosses scored, " << flagged.size() << " of "
              << all.size()
              << " left out for an energy gain across an impact beyond the tracking noise"
              << energy_gains_list(flagged) << "\n\nAt the stored parameters (" << params_path
              << "):\n";
    toss_results_table(ev.stored, false).print(std::cout);
    std::cout << "\nAt the published parameters (e = 0.125, mu = 0.18):\n";
    toss_results_table(ev.published, false).print(std::cout);
    for (const BackendTosses& r : ev.stored)
      if (!r.message.empty()) std::cout << r.name << ": " << r.message << "\n";
  }
  return 0;
}

}  // namespace rbx
