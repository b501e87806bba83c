#include "comparisons/output/predictability_report.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "comparisons/output/scorecard.h"
#include "comparisons/output/table.h"

namespace rbx {

namespace {

// A JSON number as the tables show it.
std::string num(const Json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? fmt_num(j[key].get<double>(), 2) : "-";
}

// "the physics'" / "the engine's" / "-": whose spread the step test says it is.
std::string verdict_text(const Json& b) {
  if (!b.contains("step_test")) return "-";
  const std::string v = b["step_test"].value("verdict", "none");
  return v == "physics" ? "the physics'" : v == "engine" ? "the engine's" : "-";
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
std::string scene_part(const std::string& title, const std::string& slug, const Json& e,
                       const std::string& report_dir, bool figures_ok) {
  std::ostringstream md;
  const Json& in = e["input_spread"];
  md << "### " << md_escape(title) << "\n\n"
     << e.value("count", 0L) << " copies of " << num(e, "duration") << " s at dt = " << num(e, "dt")
     << " s, every moving body "
     << "nudged by Gaussian amounts of " << num(e["perturb"], "position") << " m, "
     << num(e["perturb"], "orientation") << " rad, " << num(e["perturb"], "velocity") << " m/s and "
     << num(e["perturb"], "angular_velocity") << " rad/s per component (input spread: position "
     << num(in, "position_m") << " m, velocity " << num(in, "velocity_m_s") << " m/s).\n\n";
  bool step_test = false;
  for (const auto& [name, b] : e["backends"].items())
    step_test = step_test || b.contains("step_test");
  std::vector<std::string> header = {
      "backend",           "copies (failed)", "position spread (m)",      "5-95 % (m)",
      "orientation (rad)", "velocity (m/s)",  "amplification (position)", "(velocity)",
      "contact sequences", "clusters"};
  if (step_test) {
    header.push_back("dt / 10: spread ratio");
    header.push_back("spread is");
  }
  Table t(header);
  for (const auto& [name, b] : e["backends"].items()) {
    const Json& s = b["spread"];
    const long failed = b.value("failed", 0L);
    std::vector<std::string> cells = {
        "**" + md_escape(name) + "**",
        std::to_string(b.value("runs", 0L)) + (failed ? " (" + std::to_string(failed) + ")" : ""),
        num(s, "position_m"),
        num(s, "position_range_m"),
        num(s, "orientation_rad"),
        num(s, "velocity_m_s"),
        num(b, "amplification"),
        num(b, "velocity_amplification"),
        std::to_string(b["contact_sequences"].size()),
        std::to_string(b.value("clusters", 0))};
    if (step_test) {
      cells.push_back(b.contains("step_test") ? num(b["step_test"], "ratio") : "-");
      cells.push_back(verdict_text(b));
    }
    t.add(cells);
  }
  md << t.markdown() << "\n";
  // Each backend's most frequent contact sequence (pair:feature in the order first touched).
  md << "Most frequent contact sequence (copies of " << e.value("count", 0L) << "):\n\n";
  for (const auto& [name, b] : e["backends"].items()) {
    md << "- " << md_escape(name) << ": ";
    if (b["contact_sequences"].empty()) {
      md << (b.value("failed", 0L) > 0
                 ? "every copy failed: " + md_escape(b.value("first_failure", ""))
                 : "none")
         << "\n";
      continue;
    }
    const Json& first = b["contact_sequences"][0];
    md << md_code(first.value("sequence", "")) << " (" << first.value("copies", 0L) << ")\n";
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
    if (!evs[i].json.contains("ensemble")) continue;
    with.push_back(i);
    for (const auto& [name, b] : evs[i].json["ensemble"]["backends"].items())
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  }
  if (with.empty()) return "";
  std::vector<std::string> header = {"backend"};
  for (size_t i : with) header.push_back(md_escape(evs[i].family + "/" + scenes[i].name));
  Table t(header);
  for (const std::string& name : names) {
    std::vector<std::string> cells = {"**" + md_escape(name) + "**"};
    for (size_t i : with) {
      const Json& bs = evs[i].json["ensemble"]["backends"];
      if (!bs.contains(name)) {
        cells.push_back("·");
        continue;
      }
      const Json& b = bs[name];
      const std::string verdict = verdict_text(b);
      cells.push_back(num(b, "amplification") + (verdict == "-" ? "" : ", " + verdict));
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
    if (!evs[i].json.contains("ensemble")) continue;
    parts << scene_part(evs[i].family + "/" + scenes[i].name,
                        scene_slug(evs[i].family, scenes[i].file), evs[i].json["ensemble"],
                        report_dir, figures_ok);
  }
  if (parts.str().empty()) return "";
  return std::string("## Predictability\n\n") + kIntro + parts.str();
}

}  // namespace rbx
