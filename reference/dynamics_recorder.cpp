#include "reference/dynamics_recorder.h"

#include <algorithm>
#include <map>
#include <utility>

namespace rbx {

std::vector<RigidBody> make_bodies(const WorldDefinition& scene) {
  std::vector<RigidBody> bodies;
  bodies.reserve(scene.bodies.size());
  for (const BodySpec& spec : scene.bodies) bodies.push_back(make_body(spec));
  return bodies;
}

DynamicsRecorder::DynamicsRecorder(DynamicsResult& result, const DynamicsOptions& opt,
                                   ReadStates read_states)
    : result_(result), sample_every_(opt.sample_every), read_states_(std::move(read_states)) {}

void DynamicsRecorder::sample(double time) { result_.samples.push_back({time, read_states_()}); }

void DynamicsRecorder::start() {
  if (sample_every_ > 0) sample(0.0);
}

void DynamicsRecorder::measure_contact_laws(const SimSettings& sim) {
  measuring_ = true;
  restitution_ = sim.restitution;
  friction_ = sim.friction;
}

void DynamicsRecorder::contact(const SolvedContact& c) {
  if (measuring_) step_contacts_.push_back(c);
}

void DynamicsRecorder::contact_at_start(SolvedContact c) {
  if (!measuring_) return;
  c.centre_a = before_[static_cast<size_t>(c.a)].position;
  c.centre_b = before_[static_cast<size_t>(c.b)].position;
  step_contacts_.push_back(c);
}

void DynamicsRecorder::before_step(const std::vector<CollisionEvent>& events) {
  events_before_ = events.size();
  // Without contact laws only the step of the first impulse needs them: no reading after it.
  // With them, every step's, kept from the last step's end when it was read there.
  if ((measuring_ && !before_known_) || (!measuring_ && !result_.first_impulse.seen))
    before_ = read_states_();
  before_known_ = false;
}

void DynamicsRecorder::score_step() {
  if (step_contacts_.empty()) return;
  std::vector<BodyFinal> after = read_states_();
  for (const SolvedContact& c : step_contacts_) {
    // The relative velocity of A's material point at the contact to B's.
    auto relative = [&](const std::vector<BodyFinal>& s) {
      const BodyFinal &a = s[static_cast<size_t>(c.a)], &b = s[static_cast<size_t>(c.b)];
      return Vec3(a.velocity + a.angular_velocity.cross(c.point - c.centre_a) - b.velocity -
                  b.angular_velocity.cross(c.point - c.centre_b));
    };
    tally_.add(law_residuals({c.normal, c.depth, c.impulse, relative(before_), relative(after),
                              restitution_, friction_}));
  }
  step_contacts_.clear();
  before_ = std::move(after);
  before_known_ = true;
}

void DynamicsRecorder::first_impulse_from_step(const std::vector<CollisionEvent>& events,
                                               double dt) {
  if (result_.first_impulse.seen || events.size() <= events_before_) return;
  result_.first_impulse = first_impulse_of(
      {events.begin() + static_cast<long>(events_before_), events.end()}, before_, dt);
}

const CollisionEvent* DynamicsRecorder::first_new_event(
    const std::vector<CollisionEvent>& events) const {
  if (result_.first_impulse.seen || events.size() <= events_before_) return nullptr;
  return &events[events_before_];
}

void DynamicsRecorder::first_impulse_from_event(const CollisionEvent& first, double dt,
                                                int points) {
  result_.first_impulse = first_impulse_of({first}, before_, dt, points);
}

void DynamicsRecorder::finish_laws() {
  if (measuring_) result_.laws = tally_.summary();
}

void DynamicsRecorder::finish(const std::string& library) {
  finish_laws();
  for (BodyFinal& f : read_states_()) {
    if (!f.position.allFinite() || !f.velocity.allFinite() || !f.angular_velocity.allFinite()) {
      result_.status = Status::Error;
      result_.message = library + ": non-finite final state of " + f.name;
    }
    result_.finals.push_back(std::move(f));
  }
}

void DynamicsRecorder::after_step(long steps_taken, double time) {
  if (measuring_) score_step();
  if (sample_every_ > 0 && steps_taken % sample_every_ == 0) sample(time);
}

void append_pair_events(const std::vector<PairPoint>& points, const std::vector<RigidBody>& bodies,
                        long step, double dt, std::vector<CollisionEvent>& events) {
  std::map<std::pair<int, int>, CollisionEvent> by_pair;
  std::map<std::pair<int, int>, int> count;
  std::map<std::pair<int, int>, bool> closing;
  for (const PairPoint& p : points) {
    const std::pair<int, int> key{p.a, p.b};
    CollisionEvent& ev = by_pair[key];
    if (count[key]++ == 0) {
      ev.time = step * dt;
      ev.step = step;
      ev.body_a = bodies[p.a].name;
      ev.body_b = bodies[p.b].name;
      ev.contact = p.contact;
      ev.contact.point.setZero();
      ev.contact.normal.setZero();
      ev.contact.depth = 0.0;
    }
    ev.contact.point += p.contact.point;
    ev.contact.normal += p.contact.normal;
    ev.contact.depth = std::max(ev.contact.depth, p.contact.depth);
    ev.impulse += p.normal_impulse;
    if (p.closing) closing[key] = true;
  }
  for (auto& [key, ev] : by_pair) {
    if (!closing[key] || !(ev.impulse > 0.0)) continue;
    ev.contact.point /= count[key];
    if (ev.contact.normal.norm() > 0.0) ev.contact.normal.normalize();
    events.push_back(ev);
  }
}

}  // namespace rbx
