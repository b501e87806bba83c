#include "comparisons/eval/json_io.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include "comparisons/eval/trajectory.h"

namespace rbx {

Json to_json(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json to_json(const Quat& q) { return Json::array({q.w(), q.x(), q.y(), q.z()}); }

Json to_json(const Mat3& m) {
  Json rows = Json::array();
  for (int i = 0; i < 3; ++i) rows.push_back(Json::array({m(i, 0), m(i, 1), m(i, 2)}));
  return rows;
}

Json contact_json(const std::string& a, const std::string& b, double time, const ContactPoint& c) {
  Json j;
  j["bodies"] = Json::array({a, b});
  j["time"] = time;
  j["feature"] = c.feature;
  j["point"] = to_json(c.point);
  j["normal"] = to_json(c.normal);
  j["depth"] = c.depth;
  return j;
}

Json event_json(const CollisionEvent& e) {
  Json j = contact_json(e.body_a, e.body_b, e.time, e.contact);
  j["step"] = e.step;
  j["impulse"] = e.impulse;
  return j;
}

Json body_inputs_json(const RigidBody& b) {
  Json j;
  j["mass"] = b.mass;
  j["static"] = b.is_static;
  j["center_of_mass"] = to_json(b.position);
  j["inertia"] = to_json(b.inertia_world());
  return j;
}

Json final_json(const BodyFinal& f) {
  Json j;
  j["position"] = to_json(f.position);
  j["orientation"] = to_json(f.orientation);
  j["velocity"] = to_json(f.velocity);
  j["angular_velocity"] = to_json(f.angular_velocity);
  return j;
}

Json settings_json(const Scene& scene) {
  const SimSettings& s = scene.sim;
  Json j;
  j["dt"] = s.dt;
  j["duration"] = s.duration;
  j["gravity"] = to_json(s.gravity);
  j["restitution"] = s.restitution;
  j["friction"] = s.friction;
  j["integrator"] = s.integrator == Integrator::Euler ? "euler" : "symplectic";
  j["max_energy_ratio"] = s.max_energy_ratio;
  if (!scene.dt_study.empty()) j["dt_study"] = scene.dt_study;
  return j;
}

Json dynamics_result_json(const std::vector<RigidBody>& inputs, const DynamicsResult& r,
                          double runtime_s) {
  Json j;
  j["status"] = to_string(r.status);
  j["message"] = r.message;
  j["runtime_s"] = runtime_s;
  Json events = Json::array();
  for (const CollisionEvent& e : r.events) events.push_back(event_json(e));
  j["contacts"] = events;
  j["bodies"] = bodies_json(inputs, &r.finals);
  j["first_impulse"] = first_impulse_json(r.first_impulse);
  j["contact_laws"] = contact_laws_json(r);
  // The sampled states (DynamicsOptions::sample_every), frame by frame: one row per body of
  // position (centre of mass) and orientation (w, x, y, z).
  if (!r.samples.empty()) {
    Json time = Json::array(), states = Json::array();
    for (const StateSample& s : r.samples) {
      time.push_back(s.time);
      Json frame = Json::array();
      for (const BodyFinal& b : s.bodies)
        frame.push_back({b.position.x(), b.position.y(), b.position.z(), b.orientation.w(),
                         b.orientation.x(), b.orientation.y(), b.orientation.z()});
      states.push_back(frame);
    }
    Json names = Json::array();
    for (const BodyFinal& b : r.samples.front().bodies) names.push_back(b.name);
    j["trajectory"] = {{"time", time}, {"bodies", names}, {"states", states}};
  }
  return j;
}

Json contact_laws_json(const DynamicsResult& r) {
  const ContactLaws& laws = r.laws;
  if (!laws.measured) {
    // No impulses: the penetration its events saw at detection is all that can be scored.
    Json j = {{"measured", false}};
    if (r.events.empty()) return j;
    LawTally tally;
    for (const CollisionEvent& e : r.events) tally.add({e.contact.depth, 0.0, 0.0, 0.0, 0.0});
    const LawResidual pen = tally.summary().residuals[static_cast<int>(Law::Penetration)];
    j["contacts"] = static_cast<long>(r.events.size());
    j["penetration"] = {{"worst", pen.worst}, {"median", pen.median}};
    return j;
  }
  Json j = {{"measured", true}, {"contacts", laws.contacts}};
  for (Law law : kAllLaws) {
    const LawResidual& r = laws.residuals[static_cast<int>(law)];
    j[to_string(law)] = {{"worst", r.worst}, {"median", r.median}};
  }
  return j;
}

Json first_impulse_json(const FirstImpulse& f) {
  if (!f.seen) return nullptr;
  return {{"pair", f.body_a + "-" + f.body_b},
          {"step", f.step},
          {"contact_points", f.contact_points},
          {"normal", to_json(f.normal)},
          {"point", to_json(f.point)},
          {"depth", f.depth},
          {"impulse", f.impulse},
          {"approach_speed", f.approach_speed},
          {"entry_phase", f.entry_phase}};
}

Json bodies_json(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>* finals) {
  Json bodies = Json::object();
  for (size_t i = 0; i < inputs.size(); ++i) {
    Json b = body_inputs_json(inputs[i]);
    if (finals && i < finals->size()) b["final"] = final_json((*finals)[i]);
    bodies[inputs[i].name] = b;
  }
  return bodies;
}

void write_text(const std::string& path, const std::string& text) {
  if (path == "-") {
    std::cout << text << std::flush;
    return;
  }
  // Temporary file beside the target, then rename: readers never see a partial file.
  const std::string tmp = path + ".tmp." + std::to_string(getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + path);
    out << text;
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      throw std::runtime_error("cannot write " + path);
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write " + path);
  }
}

void write_json(const std::string& path, const Json& j) { write_text(path, j.dump(2) + "\n"); }

void put_timing(const Timing& t, Json& into) {
  // Five significant digits: a run time moves by more than that between runs, and 17 digits
  // of every timing would cost results.json a sixth of its size budget.
  into["runtime_s"] = round_sig5(t.median_s);
  into["timing"] = {{"q25_s", round_sig5(t.q25_s)},
                    {"q75_s", round_sig5(t.q75_s)},
                    {"calls", t.calls},
                    {"rounds", t.rounds},
                    {"cold_s", round_sig5(t.cold_s)}};
}

Timing timing_of(const Json& from) {
  Timing t;
  t.median_s = from.value("runtime_s", 0.0);
  if (!from.contains("timing")) return t;
  const Json& j = from["timing"];
  t.q25_s = j.value("q25_s", 0.0);
  t.q75_s = j.value("q75_s", 0.0);
  t.calls = j.value("calls", 0L);
  t.rounds = j.value("rounds", 0);
  t.cold_s = j.value("cold_s", 0.0);
  return t;
}

Stopwatch::Stopwatch()
    : start_ns_(std::chrono::duration_cast<std::chrono::nanoseconds>(
                    std::chrono::steady_clock::now().time_since_epoch())
                    .count()) {}

double Stopwatch::seconds() const {
  const long long now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                            std::chrono::steady_clock::now().time_since_epoch())
                            .count();
  return (now - start_ns_) * 1e-9;
}

}  // namespace rbx
