// Contact-law residuals of the dynamics runs (reference/contact_laws.h), summed up per backend
// and scene family for the report, the scorecard and the figures: each residual also made
// dimensionless by the scene's own scales, so that the five laws and the scenes compare.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/scene/scene.h"
#include "reference/contact_laws.h"

namespace rbx {

/// A scene's scales for the residuals: a length (the smallest moving body's size), a speed (the
/// fastest initial point speed of a moving body, at least the speed of a fall through that
/// length), and from them with the smallest moving mass an impulse and an energy.
struct LawScales {
  double length = 1.0;  // m
  double speed = 1.0;   // m/s
  double mass = 1.0;    // kg
  /// The scale of `law`'s unit: length (m), mass x speed (N s) or mass x speed^2 (J).
  double of(Law law) const;
};

/// The scales of `scene`.
LawScales law_scales(const Scene& scene);

/// One backend's residuals on one scene, read from its dynamics result (the "contact_laws"
/// object of results.json).
struct SceneLaws {
  bool measured = false;                 // the backend reported its impulses
  bool penetration_only = false;         // it did not, yet its events' depths were scored
  long contacts = 0;                     // contact points scored
  std::array<double, kLaws> worst{};     // own units
  std::array<double, kLaws> median{};    // own units
  std::array<double, kLaws> relative{};  // worst / the scene's scale
};

/// `backend`'s residuals on the scene of `ev` (`scene` its scene); measured = false when the
/// backend did not run there or reported no impulses (penetration_only: its events' depths).
SceneLaws scene_laws(const Scene& scene, const SceneEvaluation& ev, const std::string& backend);

/// The largest relative residual of `s` and its law.
std::pair<Law, double> worst_relative(const SceneLaws& s);

/// One backend on one scene family.
struct LawRow {
  std::string backend, family;
  int scenes = 0;                        // scenes with measured residuals
  int unmeasured = 0;                    // scenes it ran without reporting impulses
  double penetration_only = -1.0;        // their worst relative penetration from events (-1: none)
  long contacts = 0;                     // points scored, every scene
  std::array<double, kLaws> worst{};     // own units, the largest over the scenes
  std::array<double, kLaws> median{};    // own units, the median of the scenes' medians
  std::array<double, kLaws> relative{};  // the largest relative residual over the scenes
  std::array<std::string, kLaws> worst_scene;  // the scene of each law's largest relative one
};

/// Every (backend, family) of `backends` with a dynamics run in `evs` (`scenes` alike, in the
/// same order), families in the order first met, backends in the order given.
std::vector<LawRow> law_rows(const std::vector<Scene>& scenes,
                             const std::vector<SceneEvaluation>& evs,
                             const std::vector<std::string>& backends);

}  // namespace rbx
