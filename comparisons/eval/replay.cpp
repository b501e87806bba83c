// read_replay: a scene's result object (harness.h) read once into the typed runs a replay page
// draws (comparisons/output/view_page.h).
#include "comparisons/eval/replay.h"

#include <limits>

namespace rbx {

namespace {

// A number of the result; null (how JSON writes NaN) reads as NaN.
double number(const Json& v) {
  return v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

Vec3 vec(const Json& v) {
  if (!v.is_array() || v.size() != 3)
    return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  return {number(v[0]), number(v[1]), number(v[2])};
}

// {"time": [...], "bodies": {NAME: [[7 numbers] per frame]}}, or {} for none.
ReplayMotion read_motion(const Json& m) {
  ReplayMotion out;
  if (!m.is_object()) return out;
  if (m.contains("time") && m["time"].is_array())
    for (const Json& t : m["time"]) out.time.push_back(number(t));
  if (!m.contains("bodies") || !m["bodies"].is_object()) return out;
  for (const auto& [body, frames] : m["bodies"].items()) {
    ReplayTrack track{body, {}};
    for (const Json& f : frames) {
      ReplayPose pose;
      for (size_t k = 0; k < pose.size(); ++k)
        pose[k] = k < f.size() ? number(f[k]) : std::numeric_limits<double>::quiet_NaN();
      track.poses.push_back(pose);
    }
    out.tracks.push_back(std::move(track));
  }
  return out;
}

ReplayEvent read_event(const Json& c) {
  ReplayEvent e;
  e.time = c.contains("time") ? number(c["time"]) : 0.0;
  if (c.contains("bodies") && c["bodies"].size() == 2 && c["bodies"][0].is_string() &&
      c["bodies"][1].is_string()) {
    e.body_a = c["bodies"][0].get<std::string>();
    e.body_b = c["bodies"][1].get<std::string>();
  }
  if (c.contains("point")) e.point = vec(c["point"]);
  if (c.contains("normal")) e.normal = vec(c["normal"]);
  e.depth = c.contains("depth") ? number(c["depth"]) : 0.0;
  return e;
}

}  // namespace

const ReplayRun* Replay::run_of(const std::string& backend) const {
  for (const ReplayRun& r : runs)
    if (r.backend == backend) return &r;
  return nullptr;
}

Replay read_replay(const Json& result, size_t max_events) {
  Replay out;
  if (result.contains("backends"))
    for (const auto& [name, b] : result["backends"].items()) {
      ReplayRun run;
      run.backend = name;
      run.status = b.value("status", "");
      run.message = b.value("message", "");
      if (b.contains("trajectory")) run.motion = read_motion(b["trajectory"]);
      if (b.contains("contacts") && b["contacts"].is_array()) {
        const Json& contacts = b["contacts"];
        run.events_total = contacts.size();
        for (size_t k = 0; k < contacts.size() && k < max_events; ++k)
          run.events.push_back(read_event(contacts[k]));
      }
      out.runs.push_back(std::move(run));
    }
  return out;
}

}  // namespace rbx
