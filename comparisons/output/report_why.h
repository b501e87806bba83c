// details.md's "Why" section (report_why.cpp), apart from the rest of the report's writer.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// True when one of `lines` (a scene's disagreements or deviations) is about backend `name`.
bool mentions_backend(const std::vector<std::string>& lines, const std::string& name);

/// The why-list of details.md: for impacts, what each backend's first impulse saw against the
/// `exact` oracle; for contact queries, the first sign measured on each marked answer; then the
/// libraries' explanations whose symptom the run measured. `cols`: the backends, in column order.
std::string why_markdown(const std::vector<Scene>& scenes, const std::vector<SceneEvaluation>& evs,
                         const std::vector<std::string>& cols);

}  // namespace rbx
