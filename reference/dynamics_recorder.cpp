#include "reference/dynamics_recorder.h"

#include <utility>

namespace rbx {

std::vector<RigidBody> make_bodies(const Scene& scene) {
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

void DynamicsRecorder::before_step(const std::vector<CollisionEvent>& events) {
  events_before_ = events.size();
  // Only the step of the first impulse needs them: no reading after it.
  if (!result_.first_impulse.seen) before_ = read_states_();
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

void DynamicsRecorder::finish(const std::string& library) {
  for (BodyFinal& f : read_states_()) {
    if (!f.position.allFinite() || !f.velocity.allFinite() || !f.angular_velocity.allFinite()) {
      result_.status = Status::Error;
      result_.message = library + ": non-finite final state of " + f.name;
    }
    result_.finals.push_back(std::move(f));
  }
}

void DynamicsRecorder::after_step(long steps_taken, double time) {
  if (sample_every_ > 0 && steps_taken % sample_every_ == 0) sample(time);
}

}  // namespace rbx
