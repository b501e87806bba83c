// `rbx contacts`: every backend's contact query on every touching pair of a scene, at the t = 0
// poses or at the first step where a pair touches, each against the `exact` oracle.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/eval/patch_cover.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// One backend's answer on one pair, with its differences to the oracle.
struct ContactsRow {
  std::string backend;
  ContactRun run;
  std::string angle = "-", depth_diff = "-";  // as printed ("-": not comparable)
  std::string mark;                           // "" | "deviates" | "disagrees"
  /// The points against the exact patch (patch_cover.h), where both the backend and the oracle
  /// find a contact; its errors relative to the smaller body, as in `rbx compare`.
  std::optional<PatchCover> cover;
  double size = 0.0;  // m, the smaller body's size, what the cover's errors are relative to
};

/// One pair that some backend (or the oracle) finds touching.
struct ContactsPair {
  std::string a, b;
  ContactRun truth_run;  // the oracle's answer
  std::vector<ContactsRow> rows;
};

/// Every pair's queries, and the document `rbx contacts --json` writes.
struct ContactsComparison {
  bool at_first = false;    // --at first-contact
  long contact_step = 0;    // at_first: the step queried (-1: no pair touches within the run)
  std::string stop_reason;  // at_first: why the engine's run stopped early ("" : it did not)
  std::vector<ContactsPair> pairs;
  std::vector<std::string> marks;  // "disagrees: ..." / "deviates: ..." lines
  Json json;
};

/// Queries every pair of bodies (not both static) whose bounds meet, with every backend in
/// `names` and the oracle; `at_first` moves the bodies first with the custom engine to the first
/// step whose start has a touching pair (by the oracle's test). Marks as `rbx compare` marks:
/// clearly different from the oracle (disagrees) or beyond its round-off (deviates). Every
/// query is timed as the report times it (contact_runs: at least `budget_s` each, interleaved;
/// 0: untimed), its cold first call apart.
ContactsComparison compare_contacts(const Scene& scene, const std::vector<std::string>& names,
                                    bool at_first, double budget_s = 0.01);

}  // namespace rbx
