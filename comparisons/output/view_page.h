// The 3-D replay of one scene (`rbx view`, and one page per scene in `rbx report`): a single
// HTML file that plays every backend's run side by side with WebGL (three.js from Debian's
// libjs-three), with each event's contact point and normal and the closed form or `exact` as
// the reference.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/eval/tosses.h"
#include "comparisons/output/table.h"  // html_escape
#include "comparisons/scene/scene.h"

namespace rbx {

/// Everything a replay page draws, from the scene and its evaluation (`SceneEvaluation::json`):
/// {scene, family, description, duration, shapes: [{vertices (body frame, m), triangles}],
///  bodies: [{name, shape, static, position, orientation}] (t = 0),
///  backends: {NAME: {status, message, time: [s], frames: {BODY: [[x,y,z,qw,qx,qy,qz]]},
///            events: [{t, bodies, point, normal, depth}], events_total}},
///  reference: {source, contacts: [...], normal, depth, finals: {BODY: {velocity,
///  angular_velocity}}}}; and, when `scene_result` has one, ghost: {label, time: [s],
///  frames: {BODY: [[x,y,z,qw,qx,qy,qz]]}}, a measured trajectory drawn faintly in every panel.
/// Events beyond kViewMaxEvents per backend are counted, not listed.
Json view_data(const Scene& scene, const Json& scene_result);

/// Events listed per backend in a page (a resting stack makes thousands; the first ones show the
/// impacts, the count says how many more there were).
constexpr size_t kViewMaxEvents = 200;

/// The view data of a measured toss: every backend's simulated cube (`runs`: backend name and
/// its run, poses at the measured samples) on the toss's floor, and the measured cube as the
/// ghost. `title` names the page.
Json toss_replay_data(const Toss& toss, const std::vector<std::pair<std::string, TossRun>>& runs,
                      const std::string& title);

/// Where Debian's libjs-three installs the minified three.js (throws std::runtime_error naming
/// the package when it is absent).
std::string three_js_path();

/// The page. `three_js` is the library's source, inlined; or, when `three_src` is non-empty, the
/// page loads it from that relative path instead (the report shares one copy among its pages).
/// Every text from the scene is escaped (HTML and the embedded JSON), never parsed as markup.
/// Each backend's colour (backend_style.h) is added to the data: its toggle shows it.
std::string view_page(const Json& data, const std::string& three_js,
                      const std::string& three_src = "");

/// The report's replay pages: DIR/views/SLUG.html for every scene (sharing one copy of three.js,
/// DIR/views/three.min.js, so that 59 pages do not carry 59 copies of it; they still open
/// offline from disk); index.html links them (report_pages.h). Throws when three.js is absent.
void write_report_views(const std::string& dir, const std::vector<Scene>& scenes,
                        const std::vector<SceneEvaluation>& evs);

}  // namespace rbx
