// details.md's "Why" section: the measured first sign of every backend's miss, and the
// libraries' explanations (each pinned by a test) whose symptom the run measured.
#include "comparisons/output/report_why.h"

#include <algorithm>
#include <map>
#include <sstream>

#include "comparisons/eval/contact_cause.h"
#include "comparisons/output/scorecard.h"
#include "comparisons/output/table.h"

namespace rbx {

bool mentions_backend(const std::vector<std::string>& lines, const std::string& name) {
  for (const std::string& d : lines)
    if (d.rfind(name + " ", 0) == 0 || d.rfind(name + ":", 0) == 0) return true;
  return false;
}

namespace {

// A library's explanation of a measured sign, each pinned by a test under tests/reference/ (a
// library upgrade that changes it fails there). A sentence is printed only where its symptom is
// measured in the run: a contact sign (contact_cause.h) on one of its backends' answers, or, for
// causes with no contact sign, one of its backends marked (✗ or ~) on a scene it cites.
struct PinnedCause {
  std::vector<std::string> backends;
  std::vector<const char*> signs;   // contact_sign kinds; empty: `scenes` decides
  std::vector<std::string> scenes;  // cited scene names or "family:F"
  const char* text;
};
const std::vector<PinnedCause>& pinned_causes() {
  namespace s = contact_sign;
  static const std::vector<PinnedCause> causes = {
      {{"fcl-indep"},
       {s::kNegatedDepth, s::kWrongNormal},
       {},
       "**fcl-indep**: FCL 0.7's GST_INDEP leaves the EPA normal in A's local frame and returns "
       "the depth negated (`FclIndep.*`); its signed distance on Box-Convex aborts on an "
       "assertion (`FclIndepDistance.*`, run in a forked process)."},
      {{"fcl-hull", "libccd-mpr", "ode-hull", "mujoco-hull"},
       {s::kCentreLine},
       {},
       "**fcl-hull, libccd-mpr, ode-hull, mujoco-hull, normal along the line between the "
       "centres**: MPR follows the ray between the centres, not the minimum-translation axis "
       "(FCL issue 545): on `small_on_diagonal` n = (1, 1, 1)/sqrt(3), depth 0.26 for a true 0.15 "
       "(`FclMpr.*`, `Libccd.DiagonalCubeMprWrongEpaRight`, `MujocoKnownWrongAnswer.*`). "
       "Debian's ODE runs convex-convex through libccd MPR too, so it shares FCL's answers bit "
       "for bit."},
      {{"fcl-hull", "libccd-mpr", "libccd-epa", "ode-hull", "fcl-epa"},
       {s::kTouchingAtZeroDepth},
       {},
       "**fcl-hull, libccd-mpr, libccd-epa, ode-hull, fcl-epa at exact touching**: libccd's MPR "
       "zeroes its direction below CCD_EPS of depth, its EPA and FCL's signed distance return no "
       "direction at zero distance; the adapters report that as `touching` (no normal), a "
       "convention where the pair does touch at zero depth, scored as touching."},
      {{"libccd-epa"},
       {s::kTouchingWhenDeep},
       {},
       "**libccd-epa, touching with no normal on a penetrating pair**: libccd 2.1's "
       "ccdGJKPenetration with the box support libccd documents (a face's centre where a "
       "direction component is zero) returns depth 0 and no direction on boxes that overlap "
       "face to face (MuJoCo's BoxBoxMultiCCD, 0.1 m deep), called directly as through the "
       "adapter; with a vertex support it finds 0.1 "
       "(`Libccd.PenetratingFacePairGetsNoDirectionFromTheLibraryItself`): the library's miss, "
       "scored as one (depth error the true depth)."},
      {{"mujoco"},
       {s::kHalfDepth},
       {},
       "**mujoco, half the depth**: two boxes are queried, like its dynamics, in MuJoCo 2.2.2's "
       "own box-box collider, which reports half the depth on a face contact (the normal is "
       "right); passed on and labelled where the ratio is measured "
       "(`FairReferences.NativeBoxQueriesGiveTheFourCornerFaceManifold`)."},
      {{"bullet-sat"},
       {s::kTooDeep},
       {},
       "**bullet-sat, too deep**: the SAT + clipping path measures each point's depth to the "
       "first body's reference face, reported along the separating normal: too deep when A "
       "touches with an edge or a vertex; the normal is right "
       "(`BulletContact.KnownDefectSatDepth*`)."},
      {{"bullet-hull", "fcl-hull", "mujoco-hull"},
       {},
       {"family:mass"},
       "**mass (`-hull`)**: Bullet's hull inertia is its bounding box's; FCL 0.7's Convex inertia "
       "is off on every hull here, the box included (relative 0.5 to 5); MuJoCo's mesh inertia is "
       "exact to float round-off (`LibraryMass.*`, `scenes/mass/`)."},
      {{"dart", "dart-hull"},
       {s::kMixedNormals, s::kMissed},
       {},
       "**dart with a mesh, dart-hull**: DART 6.12 collides meshes on FCL triangle by triangle "
       "(every shape a triangle mesh: DART's default, which its mesh impacts need, "
       "`DartSettingsMeasured.FclOnTriangleMeshesAsDartRecommends`). Triangle pairs along the "
       "edge of a face contact report a side face's normal with that side's overlap (two cubes "
       "0.1 m deep: 2 of 10 points at 90 deg, 0.8 m; "
       "`DartContact.TriangleMeshPathGivesSideNormalsOnAFaceContact`), and a body wholly inside "
       "another meets no triangle and is missed (`small_on_diagonal`, `small_near_diagonal`)."},
      {{"dart", "dart-hull"},
       {},
       {"scale_mm", "scale_km"},
       "**dart, dart-hull on `scale_mm` and `scale_km`**: DART 6.12 bounces only when e times the "
       "approach speed exceeds 0.1 m/s and never faster than 100 m/s, constants compiled into its "
       "ContactConstraint (`DartSettingsMeasured.BounceLimitsAreCompiledIn`): at 1 mm/s the "
       "corner stops, at 1 km/s its bounce is capped."},
      {{"dart", "dart-hull"},
       {},
       {"family:friction"},
       "**dart, dart-hull with friction**: DART bounds each of its two friction directions by mu "
       "times the normal impulse (a pyramid, not Coulomb's cone). The adapter turns the first "
       "direction along each body's slip before every step, so a slide stops where Coulomb puts "
       "it (`DartSettingsMeasured.FirstFrictionDirectionAlongTheSlip`; with DART's own basis a "
       "slide at 45 deg to it stops short, `DartDynamics.FrictionPyramid*`); a spinning body's "
       "corners slide in directions no single first direction follows (`spin_to_rest`). Its "
       "boxed LCP takes the bounds from a pass without friction: on `tipping_box` the lifting "
       "rear corners get friction with no normal impulse and the sliding front edge 0.40 j_n "
       "for mu = 0.5, so the box slides on and tips less "
       "(`DartDynamics.BoxedFrictionBoundsComeFromAFrictionlessPass`; ODE, the same solver, the "
       "same). With no error reduction (ERP 0, measured best for impacts) `spin_landing`'s cube "
       "stays as deep as it was first seen, 0.54 mm."},
  };
  return causes;
}

// True when one of the lines is about backend `name`.
bool marks(const SceneEvaluation& ev, const std::string& name) {
  return mentions_backend(ev.disagreements, name) || mentions_backend(ev.deviations, name);
}

// The library explanations whose symptom this run measured (see PinnedCause).
std::vector<const char*> measured_pinned(const std::vector<Scene>& scenes,
                                         const std::vector<SceneEvaluation>& evs) {
  std::vector<const char*> out;
  for (const PinnedCause& p : pinned_causes()) {
    bool seen = false;
    for (size_t i = 0; i < evs.size() && !seen; ++i)
      for (const std::string& b : p.backends) {
        if (p.signs.empty()) {
          const bool cited = std::any_of(p.scenes.begin(), p.scenes.end(), [&](auto& sc) {
            return sc == scenes[i].name || sc == "family:" + evs[i].family;
          });
          seen = seen || (cited && marks(evs[i], b));
        }
        for (const Cause& c : evs[i].causes)
          for (const char* sign : p.signs)
            seen = seen || (c.check == "contact" && c.backend == b && c.kind == sign);
      }
    if (seen) out.push_back(p.text);
  }
  return out;
}

// One list of causes, per backend in `cols` order, then per kind, naming scenes and numbers.
void cause_list(std::ostringstream& md, const std::vector<Scene>& scenes,
                const std::vector<SceneEvaluation>& evs, const std::vector<std::string>& cols,
                const std::string& check) {
  std::map<std::string, std::map<std::string, std::vector<std::string>>> by;  // backend, kind
  for (size_t i = 0; i < evs.size(); ++i)
    for (const Cause& c : evs[i].causes)
      if (c.check == check)
        by[c.backend][c.kind].push_back(md_escape(scenes[i].name) + " (" + md_escape(c.detail) +
                                        ")");
  for (const std::string& b : cols) {
    if (!by.count(b)) continue;
    md << "- **" << b << "**\n";
    for (const auto& [kind, list] : by[b]) {
      md << "  - " << kind << ": ";
      for (size_t k = 0; k < list.size(); ++k) md << (k ? "; " : "") << list[k];
      md << "\n";
    }
  }
}

}  // namespace

// The why-list: for impacts, what each backend's first impulse saw against the exact oracle;
// for contact queries, the first sign measured on each marked answer; then the libraries'
// explanations whose symptom the run measured.
std::string why_markdown(const std::vector<Scene>& scenes, const std::vector<SceneEvaluation>& evs,
                         const std::vector<std::string>& cols) {
  std::ostringstream md;
  md << "## Why\n\n";
  md << "Impacts: for every backend that misses a closed form (velocity error above 0.1 %, as "
        "written or with first contact 1/3 or 2/3 of a step later), what its first impulse saw "
        "against the `exact` oracle at the poses of the step that detected it: the number of "
        "points, the normal's angle to the truth, the offset of a lone point from the true patch's "
        "centre, the impulse of that step against the closed form, the depth and entry phase at "
        "detection. Each line is the first measured sign, in that order: a wrong normal, one point "
        "on a face patch, an error only when contact begins inside a step, a contact first seen "
        "deep; else the contact was seen as the truth and the error is in the response (e.g. a "
        "soft contact).\n\n";
  const auto has = [&](const std::string& check) {
    for (const SceneEvaluation& ev : evs)
      for (const Cause& c : ev.causes)
        if (c.check == check) return true;
    return false;
  };
  if (!has("impulse")) md << "No backend misses an impact's closed form in this run.\n";
  cause_list(md, scenes, evs, cols, "impulse");
  if (has("contact")) {
    md << "\nContact queries: for every answer marked ✗ (and every `touching` answer), the first "
          "sign measured on it against the truth, in this order: touching with no normal (at "
          "zero depth, or on a penetrating pair: a miss), a missed or false contact, points with "
          "another face's normal, a normal along the line between the centres, another wrong "
          "normal; with the normal right, the depth's sign, half the depth, too deep or too "
          "shallow.\n\n";
    cause_list(md, scenes, evs, cols, "contact");
  }
  const std::vector<const char*> pinned = measured_pinned(scenes, evs);
  if (!pinned.empty()) {
    md << "\nThe libraries' explanations of the signs measured here (each pinned by a test in "
          "`tests/reference/`):\n\n";
    for (const char* t : pinned) md << "- " << t << "\n";
  }
  md << "\n";
  return md.str();
}

}  // namespace rbx
