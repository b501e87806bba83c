// The report's Predictability section (output/predictability_report.h) and the scorecard's
// predictability column (output/scorecard.h), from the ensembles' typed results.
#include "comparisons/output/predictability_report.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "comparisons/eval/ensemble.h"
#include "comparisons/output/scorecard.h"

namespace rbx {
namespace {

// One backend's ensemble: `amplification`, and a step test when `verdict` is not empty.
BackendEnsemble backend_ensemble(const std::string& name, double amplification,
                                 const std::string& verdict = "") {
  BackendEnsemble b;
  b.backend = name;
  b.runs = 50;
  b.spread.position = 1e-4;
  b.spread.position_range = 3e-4;
  b.amplification = amplification;
  b.velocity_amplification = 2.0;
  b.clusters = 2;
  b.sequences = {{"A-B:edge > A-B:face", 30}, {"A-B:face", 20}};
  if (!verdict.empty()) {
    b.step_tested = true;
    b.step_ratio = 0.1;
    b.verdict = verdict;
  }
  return b;
}

// A dynamics scene of family `family` whose backends ran ok, with an ensemble of `amplification`
// per backend (none when empty).
void add_scene(std::vector<Scene>& scenes, std::vector<SceneEvaluation>& evs,
               const std::string& family, const std::string& name,
               const std::vector<std::pair<std::string, double>>& amplification,
               const std::string& verdict = "") {
  Scene s;
  s.name = name;
  s.file = family + "/" + name + ".toml";
  s.checks = {CheckKind::Trajectory};
  SceneEvaluation ev;
  ev.family = family;
  EnsembleResult ensemble;
  ensemble.settings.count = 50;
  ensemble.dt = 1e-3;
  ensemble.duration = 0.2;
  ensemble.input.position = 1.7e-6;
  for (const auto& [b, a] : amplification) {
    ev.json["backends"][b] = {{"status", "ok"}};
    ensemble.backends.push_back(backend_ensemble(b, a, verdict));
  }
  if (!amplification.empty()) ev.ensemble = std::make_shared<const EnsembleResult>(ensemble);
  read_runs(ev);
  scenes.push_back(s);
  evs.push_back(ev);
}

TEST(Predictability, EachSceneHasItsTableWithTheStepTestsVerdictAndItsTextStaysText) {
  std::vector<Scene> scenes;
  std::vector<SceneEvaluation> evs;
  add_scene(scenes, evs, "seed", "plain", {});
  add_scene(scenes, evs, "seed", "edge_*drop*", {{"custom", 130.0}, {"ode", 250.0}}, "engine");
  const std::string md = predictability_markdown(scenes, evs, "", false);
  EXPECT_NE(md.find("## Predictability"), std::string::npos);
  // The scene's name is text, not emphasis; the one without an ensemble is not there.
  EXPECT_NE(md.find("### seed/edge\\_\\*drop\\*"), std::string::npos) << md;
  EXPECT_EQ(md.find("plain"), std::string::npos);
  // One row per backend, with its amplification and whose spread the step test says it is.
  EXPECT_NE(md.find("| **custom** | 50 | 0.0001 | 0.0003 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 1.3e+02 | 2 | 2 | 2 | 0.1 | the engine's |"), std::string::npos) << md;
  // Each backend's most frequent contact sequence, as a code span: its characters as they are (a
  // backslash escape inside a code span would be shown, not read).
  EXPECT_NE(md.find("- ode: `A-B:edge > A-B:face` (30)"), std::string::npos) << md;
  // No scene with an ensemble: no section.
  std::vector<Scene> none_s;
  std::vector<SceneEvaluation> none_e;
  add_scene(none_s, none_e, "seed", "plain", {});
  EXPECT_EQ(predictability_markdown(none_s, none_e, "", false), "");
}

TEST(Predictability, TheSummaryIsOneRowPerBackendWithTheDetailsOneLinkAway) {
  std::vector<Scene> scenes;
  std::vector<SceneEvaluation> evs;
  add_scene(scenes, evs, "seed", "plain", {});
  add_scene(scenes, evs, "seed", "edge_*drop*", {{"custom", 130.0}, {"ode", 250.0}}, "engine");
  add_scene(scenes, evs, "friction", "spin", {{"custom", 2.0}});
  const std::string md = predictability_summary_markdown(scenes, evs, "", false);
  EXPECT_NE(md.find("## Predictability"), std::string::npos);
  // A column per scene with an ensemble (its name as text), a row per backend; a backend the
  // scene did not run gets a dot; the step test's verdict where the scene has one.
  EXPECT_NE(md.find("| backend | seed/edge\\_\\*drop\\* | friction/spin |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| **custom** | 1.3e+02, the engine's | 2 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| **ode** | 2.5e+02, the engine's | · |"), std::string::npos) << md;
  // No per-scene tables or sequences: those are in details.md, linked.
  EXPECT_EQ(md.find("###"), std::string::npos) << md;
  EXPECT_EQ(md.find("A-B:edge"), std::string::npos) << md;
  EXPECT_NE(md.find("[details.md](details.md) (its section *Predictability*)"), std::string::npos)
      << md;
  std::vector<Scene> none_s;
  std::vector<SceneEvaluation> none_e;
  add_scene(none_s, none_e, "seed", "plain", {});
  EXPECT_EQ(predictability_summary_markdown(none_s, none_e, "", false), "");
}

TEST(Predictability, TheScorecardShowsTheMedianAmplificationOfAFamilysEnsembles) {
  // friction: three ensembles (custom 10, 30, 1000: median 30) and a scene without one; seed:
  // none, so its table has no predictability column.
  std::vector<Scene> scenes;
  std::vector<SceneEvaluation> evs;
  add_scene(scenes, evs, "friction", "a", {{"custom", 10.0}});
  add_scene(scenes, evs, "friction", "b", {{"custom", 1000.0}});
  add_scene(scenes, evs, "friction", "c", {{"custom", 30.0}});
  add_scene(scenes, evs, "seed", "d", {});
  evs[3].json["backends"]["custom"] = {{"status", "ok"}};
  read_runs(evs[3]);
  const std::vector<ScoreRow> rows = score_rows(scenes, evs, {"custom"});
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].predictability_text(), "30 (3)");
  EXPECT_EQ(rows[1].predictability_text(), "—");
  const std::string md = scorecard_markdown(rows);
  const size_t seed = md.find("### seed");
  ASSERT_NE(seed, std::string::npos);
  EXPECT_LT(md.find("predictability (median amplification)"), seed);
  EXPECT_EQ(md.find("predictability (median amplification)", seed), std::string::npos);
}

}  // namespace
}  // namespace rbx
