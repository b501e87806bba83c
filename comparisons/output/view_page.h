// The 3-D replay of one scene (`rbx view`, and one page per scene in `rbx report`): a single
// HTML file that plays every backend's run side by side with WebGL (three.js from Debian's
// libjs-three), with each event's contact point and normal and the closed form or `exact` as
// the reference.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/eval/replay.h"
#include "comparisons/eval/tosses.h"
#include "comparisons/output/table.h"  // html_escape
#include "comparisons/scene/scene.h"

namespace rbx {

/// A replay page's content: the header's text, and the document its script draws (`script`):
/// {scene, family, description, file, duration, shapes: [{vertices (body frame, m), triangles}],
///  bodies: [{name, shape, static, position, orientation}] (t = 0),
///  backends: {NAME: {status, message, time: [s], frames: {BODY: [[x,y,z,qw,qx,qy,qz]]},
///            events: [{t, bodies, point, normal, depth}], events_total, colour}},
///  reference: {source, contacts: [...], normal, depth, finals: {BODY: {velocity,
///  angular_velocity}}}}; and, with a ghost, ghost: {label, time: [s], frames: {BODY: [[x,y,z,
///  qw,qx,qy,qz]]}}, a measured trajectory drawn faintly in every panel.
struct ViewData {
  std::string title;                       // FAMILY/SCENE
  std::string description;                 // the scene's, as written (the page escapes it)
  double duration = 0.0;                   // s; 0: a contact query at t = 0
  std::string reference;                   // "exact", "closed form", or "" (none for this scene)
  bool reference_finals = false;           // the closed form gives final velocities
  std::optional<std::string> ghost_label;  // what the ghost is, where there is one
  Json script;
};

/// The page's content from the scene and its runs (read_replay of its evaluation, events cut
/// to kViewMaxEvents per backend: beyond that they are counted, not listed).
ViewData view_data(const Scene& scene, const Replay& replay);

/// Events listed per backend in a page (a resting stack makes thousands; the first ones show the
/// impacts, the count says how many more there were).
constexpr size_t kViewMaxEvents = 200;

/// The view data of a measured toss: every backend's simulated cube (`runs`: backend name and
/// its run, poses at the measured samples) on the toss's floor, and the measured cube as the
/// ghost. `title` names the page.
ViewData toss_replay_data(const Toss& toss,
                          const std::vector<std::pair<std::string, TossRun>>& runs,
                          const std::string& title);

/// Where Debian's libjs-three installs the minified three.js (throws std::runtime_error naming
/// the package when it is absent).
std::string three_js_path();

/// The page. `three_js` is the library's source, inlined; or, when `three_src` is non-empty, the
/// page loads it from that relative path instead (the report shares one copy among its pages).
/// Every text from the scene is escaped (HTML and the embedded JSON), never parsed as markup.
std::string view_page(const ViewData& data, const std::string& three_js,
                      const std::string& three_src = "");

/// The report's replay pages: DIR/views/SLUG.html for every scene (sharing one copy of three.js,
/// DIR/views/three.min.js, so that 59 pages do not carry 59 copies of it; they still open
/// offline from disk); index.html links them (report_pages.h). Throws when three.js is absent.
void write_report_views(const std::string& dir, const std::vector<Scene>& scenes,
                        const std::vector<SceneEvaluation>& evs);

}  // namespace rbx
