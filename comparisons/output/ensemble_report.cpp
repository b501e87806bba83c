#include "comparisons/output/ensemble_report.h"

#include <algorithm>
#include <filesystem>

#include "comparisons/output/figure_script.h"
#include "comparisons/output/table.h"

namespace rbx {

void print_ensemble(std::ostream& out, const EnsembleResult& r) {
  const Nudge& n = r.settings.nudge;
  out << "ensemble: " << r.scene << " (" << r.file << "), " << r.settings.count << " copies of "
      << fmt_num(r.duration) << " s, seed " << r.settings.seed << ", dt " << fmt_num(r.dt)
      << " s\n";
  out << "nudges (standard deviation per component): position " << fmt_num(n.position)
      << " m, orientation " << fmt_num(n.orientation) << " rad, velocity " << fmt_num(n.velocity)
      << " m/s, angular velocity " << fmt_num(n.angular_velocity) << " rad/s\n";
  out << "input spread: position " << fmt_num(r.input.position) << " m, orientation "
      << fmt_num(r.input.orientation) << " rad, velocity " << fmt_num(r.input.velocity) << " m/s\n";
  std::vector<std::string> header = {"backend",        "runs",
                                     "failed",         "position (m)",
                                     "5-95 % (m)",     "orientation (rad)",
                                     "velocity (m/s)", "amplification (position)",
                                     "(velocity)",     "sequences",
                                     "clusters"};
  const bool step_test = r.settings.step_test;
  if (step_test) {
    header.push_back("dt/10 ratio");
    header.push_back("spread is");
  }
  Table t(header);
  for (const BackendEnsemble& b : r.backends) {
    std::vector<std::string> row = {b.backend,
                                    std::to_string(b.runs),
                                    std::to_string(b.failed),
                                    fmt_num(b.spread.position),
                                    fmt_num(b.spread.position_range),
                                    fmt_num(b.spread.orientation),
                                    fmt_num(b.spread.velocity),
                                    fmt_num(b.amplification),
                                    fmt_num(b.velocity_amplification),
                                    std::to_string(b.sequences.size()),
                                    std::to_string(b.clusters)};
    if (step_test) {
      row.push_back(fmt_num(b.step_ratio));
      row.push_back(b.verdict == "physics"  ? "the physics'"
                    : b.verdict == "engine" ? "the engine's"
                                            : "-");
    }
    t.add(row);
  }
  t.print(out);
  // Each backend's most frequent contact sequences (pair:feature, in the order first touched).
  for (const BackendEnsemble& b : r.backends) {
    if (b.failed > 0)
      out << b.backend << ": " << b.failed << " copies failed, the first: " << b.first_failure
          << "\n";
    const size_t shown = std::min<size_t>(b.sequences.size(), 3);
    for (size_t i = 0; i < shown; ++i)
      out << "  " << b.backend << " sequence " << i + 1 << " (" << b.sequences[i].second
          << " copies): " << b.sequences[i].first << "\n";
    if (shown < b.sequences.size())
      out << "  " << b.backend << ": " << b.sequences.size() - shown << " more sequences\n";
  }
}

bool draw_ensemble_figures(const std::string& dir) {
  namespace fs = std::filesystem;
  return run_figure_script("ensemble_plots.py", {dir}, (fs::path(dir) / "figures.log").string()) ==
         0;
}

}  // namespace rbx
