// The figure scripts (comparisons/output/*.py): matplotlib through Debian's /usr/bin/python3.
#pragma once

#include <string>
#include <vector>

namespace rbx {

/// Runs the figure script `script` (a file name in comparisons/output/) under /usr/bin/python3
/// with `args`, its stdout and stderr into `log` (created or truncated), and the registry's
/// backend styles in RBX_BACKEND_STYLE (backend_style_json). No shell comes between:
/// every argument reaches the script as it is, whatever characters a path holds. Returns the
/// script's exit status (0: drawn); -1 when python3 is missing or could not be started, then with
/// the reason in `why`.
int run_figure_script(const std::string& script, const std::vector<std::string>& args,
                      const std::string& log, std::string* why = nullptr);

}  // namespace rbx
