// A scene library evaluated over MPI ranks and threads (`rbx report`).
#pragma once

#include <functional>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/parallel.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// Every scene through evaluate_scene, spread over the ranks and threads of `par`; on rank 0
/// the evaluations in scene order (the same for any number of ranks and threads: doubles cross
/// ranks in JSON's shortest round-trip form), elsewhere none. `on_done(i)` runs on rank 0 as
/// scene i finishes.
std::vector<SceneEvaluation> evaluate_scenes(ParallelRun& par, const std::vector<Scene>& scenes,
                                             const HarnessOptions& opt,
                                             const std::function<void(size_t)>& on_done);

}  // namespace rbx
