// What every adapter's dynamics run records the same way, whatever library steps it: a state
// sample at t = 0 and after every `sample_every` steps, the bodies' states before each step
// until the first impulse, and that first impulse from the events the step added. An adapter
// keeps its own stepping, events and checks, and calls the recorder around each step:
//
//   DynamicsRecorder rec(result, opt, read_states);
//   rec.start();
//   for each step k: rec.before_step(events); step; add events;
//                    rec.first_impulse_from_step(events, dt) (or _from_event);
//                    rec.after_step(k + 1, (k + 1) * dt);
//   rec.finish(library) (or the adapter's own finals)
//
// make_bodies (reference/backend.h), the bodies every adapter is given, is defined here too.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "reference/backend.h"

namespace rbx {

/// Samples and first impulse of one dynamics run, written into its DynamicsResult.
class DynamicsRecorder {
 public:
  /// Reads every body's state, in scene order.
  using ReadStates = std::function<std::vector<BodyFinal>()>;

  /// Records into `result` (kept by reference), sampling every `opt.sample_every` steps (0:
  /// never), reading the bodies with `read_states`.
  DynamicsRecorder(DynamicsResult& result, const DynamicsOptions& opt, ReadStates read_states);

  /// The sample at t = 0, when sampling.
  void start();
  /// Before a step: where the step's events will begin in `events` (the run's events so far)
  /// and, until the first impulse, every body's state.
  void before_step(const std::vector<CollisionEvent>& events);
  /// After a step, for libraries with one event per contact point: while no impulse was seen
  /// and the step added events to `events`, the first impulse from all of them.
  void first_impulse_from_step(const std::vector<CollisionEvent>& events, double dt);
  /// The first event the step added to `events` while no impulse was seen; else null. For
  /// libraries whose events merge a pair's points (first_impulse_from_event).
  const CollisionEvent* first_new_event(const std::vector<CollisionEvent>& events) const;
  /// The first impulse from one event, of `points` contact points as the library counts them.
  void first_impulse_from_event(const CollisionEvent& first, double dt, int points);
  /// After step number `steps_taken` (1 for the first), at simulated time `time` (s): a sample
  /// when it is a multiple of sample_every.
  void after_step(long steps_taken, double time);
  /// After the run: every body's final state; a non-finite one makes the result an error
  /// naming `library` and the body.
  void finish(const std::string& library);

 private:
  void sample(double time);

  DynamicsResult& result_;
  long sample_every_;
  ReadStates read_states_;
  std::size_t events_before_ = 0;  // the step's first event in the run's events
  std::vector<BodyFinal> before_;  // states before the step, until the first impulse
};

}  // namespace rbx
