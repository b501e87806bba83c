// The report's Predictability section: the ensembles of the scenes chosen for it (an [ensemble]
// table), each with its table per backend and its figure (comparisons/eval/ensemble.h).
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// report.md's "Predictability" section: what an ensemble measures, then per scene with one
/// (its evaluation's `ensemble`): the nudges and the input spread, a table of every backend
/// (copies run and failed, final spreads, amplification of position and velocity, contact
/// sequences, clusters, and with the step test the ratio at dt / 10 and whose spread it is),
/// each backend's most frequent contact sequence, and the scene's scatter figure when
/// `report_dir`/figures holds it (`figures_ok`). "" when no scene has an ensemble.
std::string predictability_markdown(const std::vector<Scene>& scenes,
                                    const std::vector<SceneEvaluation>& evs,
                                    const std::string& report_dir, bool figures_ok);

/// The same section as report.md's summary shows it: one table, a row per backend and a column
/// per scene with an ensemble, each cell the position amplification and, with the step test,
/// whose spread it is; then the scenes' figures; the full tables are named in details.md. ""
/// when no scene has an ensemble.
std::string predictability_summary_markdown(const std::vector<Scene>& scenes,
                                            const std::vector<SceneEvaluation>& evs,
                                            const std::string& report_dir, bool figures_ok);

}  // namespace rbx
