// How a pair's answers stand against the answer its scene states ([expect.distance],
// [expect.toi]): the oracle's and those of the engines [expect] binds, each judged as `rbx
// distance` and `rbx toi` judge their rows against the oracle.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// The first pair's check against the scene's stated answer.
struct StatedCheck {
  std::string stated;                    // the stated answer, one line ("": none stated)
  std::vector<std::string> met, missed;  // "exact" and the bound engines asked for
  /// The bound engines that miss it, less one [expect] known_failure excuses: the scene fails
  /// (the command's exit status 1), as `rbx compare` fails a scene on its [expect].
  std::vector<std::string> failing;
  /// The engine known_failure excuses, when it misses.
  std::string excused;
};

/// Files `name`'s verdict into `c`: missed when `disagrees`.
inline void file_stated(StatedCheck& c, const Expect& e, const std::string& name, bool disagrees) {
  (disagrees ? c.missed : c.met).push_back(name);
  if (!disagrees || name == "exact") return;
  if (e.known_failure.rfind(name + ": ", 0) == 0)
    c.excused = name;
  else
    c.failing.push_back(name);
}

/// The check as the commands' JSON carries it (docs/contract.md).
inline Json stated_json(const StatedCheck& c) {
  return {{"stated", c.stated},
          {"met", c.met},
          {"missed", c.missed},
          {"failing", c.failing},
          {"excused", c.excused}};
}

/// Whether `name` is an engine [expect] binds.
inline bool bound_by(const Expect& e, const std::string& name) {
  return std::find(e.engines.begin(), e.engines.end(), name) != e.engines.end();
}

}  // namespace rbx
