// Default paths of the rbx command (scenes/, reports/...), resolved inside the repository the
// binary was built from, so that `rbx report` works from any directory.
#pragma once

#include <string>

namespace rbx {

/// A default repository path, `relative` to the repository root (e.g. "scenes",
/// "reports/baseline.json"). Run from the repository root it is `relative` itself, unchanged (so
/// file names in outputs stay "scenes/..."); from anywhere else it is the path inside the source
/// tree compiled in (RBX_DEFAULT_SOURCE_DIR). Paths the caller gives are never passed through this.
std::string default_repo_path(const std::string& relative);

}  // namespace rbx
