#include "comparisons/output/view_page.h"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "asset_view_css.h"
#include "asset_view_js.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/trajectory.h"
#include "comparisons/output/backend_style.h"
#include "comparisons/output/scorecard.h"
#include "comparisons/output/table.h"
#include "comparisons/scene/scene_file.h"

namespace fs = std::filesystem;

namespace rbx {

namespace {

Json vec_json(const Vec3& v) { return {round_sig5(v.x()), round_sig5(v.y()), round_sig5(v.z())}; }

// A run's events (or t = 0 contacts), at most kViewMaxEvents, rounded for the page.
Json events_json(const std::vector<ReplayEvent>& events) {
  Json out = Json::array();
  for (const ReplayEvent& e : events)
    if (out.size() < kViewMaxEvents)
      out.push_back({{"t", round_sig5(e.time)},
                     {"bodies", {e.body_a, e.body_b}},
                     {"point", vec_json(e.point)},
                     {"normal", vec_json(e.normal)},
                     {"depth", round_sig5(e.depth)}});
  return out;
}

// A motion's "time" (s) and "frames" ({BODY: [[x, y, z, qw, qx, qy, qz]]}), put into `into`.
void put_motion(const ReplayMotion& m, Json& into) {
  into["time"] = m.time;
  into["frames"] = Json::object();
  for (const ReplayTrack& t : m.tracks) {
    Json frames = Json::array();
    for (const ReplayPose& p : t.poses) frames.push_back(p);
    into["frames"][t.body] = frames;
  }
}

// JSON inside a <script> element: no "<", ">" or "&" (their \u escapes mean the same in JSON
// strings, and they occur nowhere else), so no scene text can close the element.
std::string script_safe_json(const Json& j) {
  const std::string s = j.dump(-1, ' ', false, Json::error_handler_t::replace);
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    if (c == '<')
      out += "\\u003c";
    else if (c == '>')
      out += "\\u003e";
    else if (c == '&')
      out += "\\u0026";
    else
      out += c;
  }
  return out;
}

}  // namespace

ViewData view_data(const Scene& scene, const Replay& replay) {
  Json d;
  d["scene"] = scene.name;
  d["family"] = scene_family(scene.file);
  d["description"] = scene.description;
  d["file"] = scene.file;
  d["duration"] = scene.sim.duration;
  // Shapes in the body frame (centre of mass at the origin), shared between identical bodies.
  d["shapes"] = Json::array();
  d["bodies"] = Json::array();
  std::map<std::string, size_t> shape_index;
  for (const RigidBody& b : make_bodies(scene)) {
    Json verts = Json::array();
    for (const Vec3& v : b.shape->vertices()) verts.push_back(vec_json(v));
    Json tris = Json::array();
    for (const auto& t : b.shape->triangles()) tris.push_back({t[0], t[1], t[2]});
    Json shape = {{"vertices", verts}, {"triangles", tris}};
    const std::string key = shape.dump();
    auto it = shape_index.find(key);
    if (it == shape_index.end()) {
      it = shape_index.emplace(key, d["shapes"].size()).first;
      d["shapes"].push_back(shape);
    }
    const Quat q = b.orientation.normalized();
    d["bodies"].push_back(
        {{"name", b.name},
         {"shape", it->second},
         {"static", b.is_static},
         {"position", vec_json(b.position)},
         {"orientation",
          {round_sig5(q.w()), round_sig5(q.x()), round_sig5(q.y()), round_sig5(q.z())}}});
  }
  // Each backend: status, sampled trajectory, events.
  d["backends"] = Json::object();
  for (const ReplayRun& run : replay.runs) {
    Json v = {{"status", run.status}, {"message", run.message}};
    put_motion(run.motion, v);
    v["events"] = events_json(run.events);
    v["events_total"] = run.events_total;
    v["colour"] = backend_colour(run.backend);  // its toggle and label show it, as figures do
    d["backends"][run.backend] = v;
  }
  // The reference: the closed form where the scene gives one, else the exact oracle's contacts.
  Json ref = {{"source", ""}, {"contacts", Json::array()}, {"finals", Json::object()}};
  ViewData out;
  const ReplayRun* exact = replay.run_of("exact");
  if (exact && scene.has_check(CheckKind::Contact)) {
    out.reference = "exact";
    ref["source"] = "exact";
    ref["contacts"] = events_json(exact->events);
  }
  if (scene.expect) {
    if (scene.expect->contact && scene.expect->contact->normal) {
      out.reference = "closed form";
      ref["source"] = "closed form";
      const Json normal = vec_json(scene.expect->contact->normal->normalized());
      ref["normal"] = normal;
      if (scene.expect->contact->depth) ref["depth"] = round_sig5(*scene.expect->contact->depth);
      // Drawn at the exact oracle's deepest point when there is one (the closed form gives no
      // point in most scenes).
      for (Json& c : ref["contacts"]) c["normal"] = normal;
    }
    for (const ExpectBody& e : scene.expect->bodies) {
      if (!e.velocity && !e.angular_velocity) continue;
      out.reference = "closed form";
      out.reference_finals = true;
      ref["source"] = "closed form";
      Json f = Json::object();
      if (e.velocity) f["velocity"] = vec_json(*e.velocity);
      if (e.angular_velocity) f["angular_velocity"] = vec_json(*e.angular_velocity);
      ref["finals"][e.name] = f;
    }
  }
  d["reference"] = ref;
  if (replay.ghost) {
    d["ghost"] = {{"label", replay.ghost_label}};
    put_motion(*replay.ghost, d["ghost"]);
    out.ghost_label = replay.ghost_label;
  }
  out.title = scene_family(scene.file) + "/" + scene.name;
  out.description = scene.description;
  out.duration = scene.sim.duration;
  out.script = std::move(d);
  return out;
}

ViewData toss_replay_data(const Toss& toss,
                          const std::vector<std::pair<std::string, TossRun>>& runs,
                          const std::string& title) {
  auto pose = [](const Vec3& p, const Quat& q) {
    const Quat u = q.normalized();
    return ReplayPose{round_sig5(p.x()), round_sig5(p.y()), round_sig5(p.z()), round_sig5(u.w()),
                      round_sig5(u.x()), round_sig5(u.y()), round_sig5(u.z())};
  };
  const double t0 = toss.samples.front().time, rate = CubeTossModel{}.sample_rate;
  Replay replay;
  replay.ghost_label = "the measured cube (motion capture)";
  replay.ghost = ReplayMotion{{}, {ReplayTrack{"cube", {}}}};
  for (const TossSample& s : toss.samples) {
    replay.ghost->time.push_back(round_sig5(s.time - t0));
    replay.ghost->tracks[0].poses.push_back(pose(s.position, s.orientation));
  }
  for (const auto& [name, run] : runs) {
    ReplayRun r;
    r.backend = name;
    r.status = to_string(run.status);
    r.message = run.message;
    r.motion.tracks.push_back({"cube", {}});
    if (run.status == Status::Ok)
      for (size_t i = 0; i < run.track.position.size(); ++i) {
        r.motion.time.push_back(round_sig5(i / rate));  // sample i of the run is measured sample i
        r.motion.tracks[0].poses.push_back(pose(run.track.position[i], run.track.orientation[i]));
      }
    replay.runs.push_back(std::move(r));
  }
  // The toss's own scene: the cube at its first sample and the floor.
  Scene scene = toss_scene(toss, kPublishedParams);
  scene.name = title;
  scene.file = "real/cube_toss_" + std::to_string(toss.id) + ".toml";
  scene.description =
      "A measured toss of the ContactNets cube, replayed by every backend at its "
      "fitted parameters; the grey ghost is the measurement.";
  return view_data(scene, replay);
}

std::string three_js_path() {
  for (const char* p : {"/usr/share/javascript/three/three.min.js",
                        "/usr/share/javascript/three/build/three.min.js"})
    if (fs::exists(p)) return p;
  throw std::runtime_error(
      "three.js not found under /usr/share/javascript/three/ (install Debian's libjs-three)");
}

std::string view_page(const ViewData& data, const std::string& three_js,
                      const std::string& three_src) {
  const std::string& title = data.title;
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>rbx view: "
    << html_escape(title) << "</title>\n<style>\n"
    << kViewStyle << "</style>\n";
  if (!three_src.empty())
    h << "<script src=\"" << html_escape(three_src) << "\"></script>\n";
  else
    h << "<script>" << three_js << "</script>\n";
  h << "</head><body>\n<header><h1>" << html_escape(title) << "</h1>\n";
  if (!data.description.empty()) h << "<p>" << html_escape(data.description) << "</p>\n";
  h << "<p>One panel per backend, same camera (drag to orbit, wheel to zoom). Red: the backend's "
       "contact points and normals (from B toward A) of the events near the current time"
    << (data.duration > 0 ? "" : " (contact query at t = 0)") << ". Black: the reference ("
    << html_escape(data.reference.empty() ? "none for this scene" : data.reference) << ")";
  if (data.reference_finals)
    h << "; at the end of the run, arrows give the closed-form final velocity direction";
  if (data.ghost_label)
    h << ". Grey ghost in every panel: " << html_escape(*data.ghost_label)
      << " (shown with the reference)";
  h << ". Trajectories are sampled (at most " << kMaxFrames
    << " frames, thinned to key frames and interpolated between them); at most " << kViewMaxEvents
    << " events per backend are drawn.</p>\n<div id=\"controls\"><button id=\"play\">play</button> "
       "<input id=\"slider\" type=\"range\" min=\"0\" max=\"1000\" value=\"0\"> <span "
       "id=\"clock\"></span> "
       "<label><input id=\"ref\" type=\"checkbox\" checked> reference</label> <span "
       "id=\"toggles\"></span></div>\n"
       "</header>\n<div id=\"stage\"><canvas id=\"view\"></canvas><div id=\"labels\"></div></div>\n"
       "<pre id=\"rbx-state\">{}</pre>\n<script id=\"rbx-data\" type=\"application/json\">"
    << script_safe_json(data.script) << "</script>\n<script>\n"
    << kViewScript << "</script>\n</body></html>\n";
  return h.str();
}

void write_report_views(const std::string& dir, const std::vector<Scene>& scenes,
                        const std::vector<SceneEvaluation>& evs) {
  const fs::path views = fs::path(dir) / "views";
  fs::create_directories(views);
  fs::copy_file(three_js_path(), views / "three.min.js", fs::copy_options::overwrite_existing);
  for (size_t i = 0; i < scenes.size() && i < evs.size(); ++i) {
    const std::string slug = scene_slug(evs[i].family, scenes[i].file);
    write_text((views / (slug + ".html")).string(),
               view_page(view_data(scenes[i], read_replay(evs[i].json, kViewMaxEvents)), "",
                         "three.min.js"));
  }
}

}  // namespace rbx
