// What every adapter's dynamics run records the same way, whatever library steps it: a state
// sample at t = 0 and after every `sample_every` steps, the bodies' states before each step
// until the first impulse, that first impulse from the events the step added, and the
// contact-law residuals (reference/contact_laws.h) of every contact point the library reports
// with its impulse. An adapter keeps its own stepping, events and checks, and calls the
// recorder around each step:
//
//   DynamicsRecorder rec(result, opt, read_states);
//   rec.measure_contact_laws(scene.sim);
//   rec.start();
//   for each step k: rec.before_step(events); step; add events;
//                    rec.first_impulse_from_step(events, dt) (or _from_event);
//                    rec.contact(...) or rec.contact_at_start(...) per solved point;
//                    rec.after_step(k + 1, (k + 1) * dt);
//   rec.finish(library) (or the adapter's own finals and rec.finish_laws())
//
// make_bodies (reference/backend.h), the bodies every adapter is given, is defined here too.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "engine/world_state.h"
#include "reference/backend.h"
#include "reference/contact_laws.h"

namespace rbx {

/// Samples and first impulse of one dynamics run, written into its DynamicsResult.
class DynamicsRecorder {
 public:
  /// Reads every body's state, in scene order.
  using ReadStates = std::function<std::vector<BodyFinal>()>;

  /// Records into `result` (kept by reference), sampling every `opt.sample_every` steps (0:
  /// never), reading the bodies with `read_states`.
  DynamicsRecorder(DynamicsResult& result, const DynamicsOptions& opt, ReadStates read_states);

  /// Scores every contact point given by contact() against the laws of the scene's `sim` (its
  /// restitution and friction) after each step, and follows the friction its bodies receive
  /// beyond the cone (ConeExcess); the result's `laws` are filled from then on.
  void measure_contact_laws(const WorldDefinition& scene);
  /// One contact point the step solved, its impulse as the library reports it and the bodies'
  /// centres of mass at its detection (the velocities' lever arms).
  void contact(const SolvedContact& c);
  /// The same, detected at the step's start poses (as the libraries detect): the centres are
  /// the bodies' positions before the step.
  void contact_at_start(SolvedContact c);
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
  /// After the run: the contact-law residuals into the result (finish does it too).
  void finish_laws();
  /// After the run: the contact-law residuals and every body's final state; a non-finite one makes
  /// the result an error naming `library` and the body.
  void finish(const std::string& library);

 private:
  void sample(double time);
  // Scores the step's contacts against the states after it.
  void score_step(double dt);
  // Follows the friction beyond the cone of the step's contacts (ConeExcess).
  void follow_cone_excess(double dt);

  DynamicsResult& result_;
  long sample_every_;
  ReadStates read_states_;
  std::size_t events_before_ = 0;  // the step's first event in the run's events
  std::vector<BodyFinal> before_;  // states before the step (every step when measuring)
  bool measuring_ = false;         // contact laws measured
  bool before_known_ = false;      // before_ holds the states at the coming step's start
  double restitution_ = 0.0, friction_ = 0.0;  // the scene's laws
  std::vector<SolvedContact> step_contacts_;   // the step's scored points
  LawTally tally_;
  double last_time_ = 0.0;  // simulated time at the last step's end
  // Per body: its mass and body-frame inertia (static: mass 0), and the friction beyond the cone
  // followed so far with the spin it gave (rad/s).
  std::vector<double> mass_;
  std::vector<Mat3> inertia_body_;
  std::vector<ConeExcess> cone_excess_;
  std::vector<double> excess_spin_;
};

/// One contact point a library solved in a step, for events merged per pair (libraries that
/// solve a pair at several points but report no impulse per pair: ODE, DART).
struct PairPoint {
  int a = 0, b = 0;             // scene indices, a < b
  ContactPoint contact;         // ours: normal from b toward a
  double normal_impulse = 0.0;  // N s, on a along the normal over the step
  bool closing = false;         // a approached b at this point before the step
};

/// Appends the events of step `step` to `events`, in pair order: one per pair with a closing
/// point whose normal impulses sum to a push; its point and normal the means over the pair's
/// points, its depth the largest, its impulse the sum.
void append_pair_events(const std::vector<PairPoint>& points, const std::vector<RigidBody>& bodies,
                        long step, double dt, std::vector<CollisionEvent>& events);

}  // namespace rbx
