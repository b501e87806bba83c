#include "comparisons/output/predictability_report.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "comparisons/eval/ensemble.h"
#include "comparisons/output/scorecard.h"
#include "comparisons/output/table.h"

namespace rbx {

namespace {

// A number as the tables show it.
std::string two_digits(double x) { return fmt_num(x, 2); }

// "the physics'" / "the engine's" / "-": whose spread the step test says it is.
std::string verdict_text(const BackendEnsemble& b) {
  if (!b.step_tested) return "-";
  return b.verdict == "physics" ? "the physics'" : b.verdict == "engine" ? "the engine's" : "-";
}

// Backend `name`'s ensemble in `e`, or null.
const BackendEnsemble* backend_in(const EnsembleResult& e, const std::string& name) {
  for (const BackendEnsemble& b : e.backends)
    if (b.backend == name) return &b;
  return nullptr;
}

// The figure line of a scene's ensemble, when the figure was drawn.
std::string figure_line(const std::string& title, const std::string& slug,
                        const std::string& report_dir, bool figures_ok) {
  const std::string file = "figures/ensemble_" + slug + ".png";
  if (!figures_ok || !std::filesystem::exists(std::filesystem::path(report_dir) / file)) return "";
  return "![final positions of the copies, " + md_escape(title) + "](" + md_url(file) + ")\n\n";
}

// What the section measures, as both versions open it.
const char* kIntro =
    "How far each engine's outcome spreads when the start is nudged by a tiny random "
    "amount (Chung & Pollard 2016: a tuned engine can take another sequence of contacts, "
    "and end elsewhere, after a change far below any measurement). Each scene with an "
    "`[ensemble]` table runs that many nudged copies through every dynamics backend "
    "(docs/ensemble.md). *Spread*: the root mean square distance of the copies' final "
    "states from their mean, the largest over the moving bodies; *amplification*: that "
    "spread over the input's (order 1: the outcome is as smooth as the nudge; thousands: a "
    "discontinuity was crossed); *contact sequences*: the distinct orders in which pairs "
    "and features (face, edge, vertex) first touch; *clusters*: groups of final positions. "
    "With the step test the same copies run at a ten times smaller step: a spread that "
    "stays (ratio 0.5 to 2) is the physics' (the truth itself is that sensitive), one that "
    "changes is the engine's. The scorecard's *predictability* is the median position "
    "amplification over a family's ensembles.\n\n";

// One scene's part: its nudges, the table, the sequences and the figure.
std::string scene_part(const std::string& title, const std::string& slug, const EnsembleResult& e,
                       const std::string& report_dir, bool figures_ok) {
  std::ostringstream md;
  const Nudge& nudge = e.settings.nudge;
  md << "### " << md_escape(title) << "\n\n"
     << e.settings.count << " copies of " << two_digits(e.duration)
     << " s at dt = " << two_digits(e.dt) << " s, every moving body nudged by Gaussian amounts of "
     << two_digits(nudge.position) << " m, " << two_digits(nudge.orientation) << " rad, "
     << two_digits(nudge.velocity) << " m/s and " << two_digits(nudge.angular_velocity)
     << " rad/s per component (input spread: position " << two_digits(e.input.position)
     << " m, velocity " << two_digits(e.input.velocity) << " m/s).\n\n";
  const bool step_test = std::any_of(e.backends.begin(), e.backends.end(),
                                     [](const BackendEnsemble& b) { return b.step_tested; });
  std::vector<std::string> header = {
      "backend",           "copies (failed)", "position spread (m)",      "5-95 % (m)",
      "orientation (rad)", "velocity (m/s)",  "amplification (position)", "(velocity)",
      "contact sequences", "clusters"};
  if (step_test) {
    header.push_back("dt / 10: spread ratio");
    header.push_back("spread is");
  }
  Table t(header);
  for (const BackendEnsemble& b : e.backends) {
    std::vector<std::string> cells = {
        "**" + md_escape(b.backend) + "**",
        std::to_string(b.runs) + (b.failed ? " (" + std::to_string(b.failed) + ")" : ""),
        two_digits(b.spread.position),
        two_digits(b.spread.position_range),
        two_digits(b.spread.orientation),
        two_digits(b.spread.velocity),
        two_digits(b.amplification),
        two_digits(b.velocity_amplification),
        std::to_string(b.sequences.size()),
        std::to_string(b.clusters)};
    if (step_test) {
      cells.push_back(b.step_tested ? two_digits(b.step_ratio) : "-");
      cells.push_back(verdict_text(b));
    }
    t.add(cells);
  }
  md << t.markdown() << "\n";
  // Each backend's most frequent contact sequence (pair:feature in the order first touched).
  md << "Most frequent contact sequence (copies of " << e.settings.count << "):\n\n";
  for (const BackendEnsemble& b : e.backends) {
    md << "- " << md_escape(b.backend) << ": ";
    if (b.sequences.empty()) {
      md << (b.failed > 0 ? "every copy failed: " + md_escape(b.first_failure) : "none") << "\n";
      continue;
    }
    md << md_code(b.sequences.front().first) << " (" << b.sequences.front().second << ")\n";
  }
  md << "\n" << figure_line(title, slug, report_dir, figures_ok);
  return md.str();
}

}  // namespace

std::string predictability_summary_markdown(const std::vector<Scene>& scenes,
                                            const std::vector<SceneEvaluation>& evs,
                                            const std::string& report_dir, bool figures_ok) {
  std::vector<size_t> with;        // scenes with an ensemble
  std::vector<std::string> names;  // backends, in the order the ensembles list them
  for (size_t i = 0; i < scenes.size() && i < evs.size(); ++i) {
    if (!evs[i].ensemble) continue;
    with.push_back(i);
    for (const BackendEnsemble& b : evs[i].ensemble->backends)
      if (std::find(names.begin(), names.end(), b.backend) == names.end())
        names.push_back(b.backend);
  }
  if (with.empty()) return "";
  std::vector<std::string> header = {"backend"};
  for (size_t i : with) header.push_back(md_escape(evs[i].family + "/" + scenes[i].name));
  Table t(header);
  for (const std::string& name : names) {
    std::vector<std::string> cells = {"**" + md_escape(name) + "**"};
    for (size_t i : with) {
      const BackendEnsemble* b = backend_in(*evs[i].ensemble, name);
      if (!b) {
        cells.push_back("·");
        continue;
      }
      const std::string verdict = verdict_text(*b);
      cells.push_back(two_digits(b->amplification) + (verdict == "-" ? "" : ", " + verdict));
    }
    t.add(cells);
  }
  std::ostringstream md;
  md << "## Predictability\n\n"
     << kIntro
     << "Each cell: the position amplification and, where the scene asks for the step test, "
        "whose spread it is. Every scene's table (spreads, copies failed, contact sequences, "
        "clusters, the ratio at dt / 10) and each backend's most frequent contact sequence: "
        "[details.md](details.md) (its section *Predictability*).\n\n"
     << t.markdown() << "\n";
  for (size_t i : with)
    md << figure_line(evs[i].family + "/" + scenes[i].name,
                      scene_slug(evs[i].family, scenes[i].file), report_dir, figures_ok);
  return md.str();
}

std::string predictability_markdown(const std::vector<Scene>& scenes,
                                    const std::vector<SceneEvaluation>& evs,
                                    const std::string& report_dir, bool figures_ok) {
  std::ostringstream parts;
  for (size_t i = 0; i < scenes.size() && i < evs.size(); ++i) {
    if (!evs[i].ensemble) continue;
    parts << scene_part(evs[i].family + "/" + scenes[i].name,
                        scene_slug(evs[i].family, scenes[i].file), *evs[i].ensemble, report_dir,
                        figures_ok);
  }
  if (parts.str().empty()) return "";
  return std::string("## Predictability\n\n") + kIntro + parts.str();
}

}  // namespace rbx
