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

void DynamicsRecorder::measure_contact_laws(const WorldDefinition& scene) {
  measuring_ = true;
  restitution_ = scene.sim.restitution;
  friction_ = scene.sim.friction;
  for (const RigidBody& b : make_bodies(scene)) {
    mass_.push_back(b.is_static ? 0.0 : b.mass);
    inertia_body_.push_back(b.inertia_body);
  }
  cone_excess_.assign(mass_.size(), ConeExcess{});
  excess_spin_.assign(mass_.size(), 0.0);
}

void DynamicsRecorder::follow_cone_excess(double dt) {
  // Below this speed (m/s) a body counts as at rest, its spin held by static friction.
  constexpr double kRestSpeed = 1e-3;
  // A library's friction directions are perpendicular to the normal to round-off only, so a
  // point left at exactly no normal impulse reads +-1e-21 N s or so: the load and the excess
  // are judged against the step's largest normal impulse.
  double largest = 0.0;
  for (const SolvedContact& c : step_contacts_)
    largest = std::max(largest, std::abs(c.impulse.dot(c.normal)));
  const size_t n = mass_.size();
  std::vector<double> torque(n, 0.0), damping(n, 0.0), push(n, 0.0);
  std::vector<long> points(n, 0);
  std::vector<bool> touched(n, false);
  for (const SolvedContact& c : step_contacts_) {
    const double jn = c.impulse.dot(c.normal);
    for (const int side : {c.a, c.b}) {
      const size_t i = static_cast<size_t>(side);
      if (i >= n || mass_[i] <= 0.0) continue;
      // The body's view: the normal out of the other body into it, the impulse it received.
      const double sign = side == c.a ? 1.0 : -1.0;
      const Vec3 normal = sign * c.normal, impulse = sign * c.impulse;
      const Vec3 r = c.point - (side == c.a ? c.centre_a : c.centre_b);
      const Vec3 v = before_[i].velocity - before_[i].velocity.dot(normal) * normal;
      const double speed = v.norm();
      touched[i] = true;
      if (jn > 1e-9 * largest && speed > kRestSpeed) {
        const double lever = r.dot(v / speed);
        damping[i] += friction_ * jn * lever * lever / speed;
      }
      const Vec3 jt = impulse - impulse.dot(normal) * normal;
      const double excess = jt.norm() - friction_ * std::max(jn, 0.0);
      if (!(excess > 1e-6 * friction_ * largest) || jt.norm() == 0.0) continue;
      const Vec3 beyond = jt * (excess / jt.norm());
      ++points[i];
      torque[i] += r.cross(beyond).dot(normal);
      if (speed > kRestSpeed) push[i] += beyond.dot(v / speed) * speed / mass_[i];
    }
  }
  for (size_t i = 0; i < n; ++i) {
    if (!touched[i]) continue;
    const Vec3 v = before_[i].velocity;
    // The axis: the first contact's normal into this body (a box on one surface has one).
    Vec3 axis = Vec3::Zero();
    for (const SolvedContact& c : step_contacts_)
      if (static_cast<size_t>(c.a) == i || static_cast<size_t>(c.b) == i) {
        axis = static_cast<size_t>(c.a) == i ? c.normal : Vec3(-c.normal);
        break;
      }
    const Mat3 rot = before_[i].orientation.toRotationMatrix();
    const double inertia = axis.dot(rot * inertia_body_[i] * rot.transpose() * axis);
    const double speed = (v - v.dot(axis) * axis).norm();
    // The step's friction directions are set from the velocities it starts with (Bullet, ODE
    // and DART fix them before solving), so its friction damps the spin brought into it, and the
    // spin its own excess adds meets friction from the next step.
    double& spin = excess_spin_[i];
    spin = speed <= kRestSpeed || !(inertia > 0.0)
               ? 0.0
               : spin / (1.0 + damping[i] / inertia) + torque[i] / inertia;
    ConeExcess& u = cone_excess_[i];
    u.body = static_cast<int>(i);
    u.points += points[i];
    u.turn_rad += spin * dt;
    u.push_m2s2 += push[i];
  }
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

void DynamicsRecorder::score_step(double dt) {
  if (step_contacts_.empty()) return;
  follow_cone_excess(dt);
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
  if (!measuring_) return;
  result_.laws = tally_.summary();
  for (const ConeExcess& u : cone_excess_)
    if (u.points > 0) result_.laws.cone_excess.push_back(u);
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
  if (measuring_) score_step(time - last_time_);
  last_time_ = time;
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
