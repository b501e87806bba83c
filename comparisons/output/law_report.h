// The contact laws in the report: report.md's section (per family, each backend's worst and
// median residual of every law, and the figure), details.md's table per scene, and laws.csv,
// the numbers behind both (comparisons/eval/law_residuals.h).
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// report.md's "Contact laws" section: what is measured, one table of every backend in
/// `backends` by scene family (the largest relative residual and its law), and each family's
/// figure when `report_dir`/figures holds it (`figures_ok`). "" when no dynamics run was scored.
std::string contact_laws_markdown(const std::vector<Scene>& scenes,
                                  const std::vector<SceneEvaluation>& evs,
                                  const std::vector<std::string>& backends,
                                  const std::string& report_dir, bool figures_ok);

/// details.md's "Contact laws": per scene family a table of every backend (points scored, each
/// law's worst and median in its own unit, the largest relative residual with its law and
/// scene; backends that reported no impulses named), then scene_laws_markdown.
std::string contact_laws_details_markdown(const std::vector<Scene>& scenes,
                                          const std::vector<SceneEvaluation>& evs,
                                          const std::vector<std::string>& backends);

/// The table per scene: every scene and backend with scored contact points, each law's worst
/// and median. "" when there are none.
std::string scene_laws_markdown(const std::vector<Scene>& scenes,
                                const std::vector<SceneEvaluation>& evs,
                                const std::vector<std::string>& backends);

/// laws.csv: scene, family, backend, law, unit, worst, median, scale, relative (worst / scale),
/// contacts; one row per (scene, backend, law) with scored contact points.
std::string laws_csv(const std::vector<Scene>& scenes, const std::vector<SceneEvaluation>& evs,
                     const std::vector<std::string>& backends);

}  // namespace rbx
