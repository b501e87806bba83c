// Library calls that cannot take rbx down: an abort, a crash or an endless loop inside one
// library becomes that backend's `error` or `timeout`, and the run goes on with the others.
//
// Design: a library call runs in a child process that the caller supervises. Two ways:
// - one call, one child (`isolated`): a fork per call, for commands that make few calls.
// - a block of work items in one child (`run_items_isolated`, used by ParallelRun::map): the
//   child runs item after item and says "call begins" / "call ends" around every library call
//   made through `isolated`, so the parent knows which backend is running and since when. A
//   call past its deadline is killed with the child; a child that dies inside a call names that
//   call. Either way the failure is recorded for (item, backend) and a new child (a fresh fork,
//   so it sees the record) starts again at that item, where every call of that backend answers
//   with the recorded failure at once. A fork here costs milliseconds, so one per block keeps
//   explore's 20,000 samples and the report's scenes near their in-process cost.
// In-process alternatives were weighed and rejected: a signal that longjmps out of a library
// stuck in a loop can leave malloc's lock held (libccd's EPA allocates every iteration), and a
// thread cannot be stopped at all.
#pragma once

#include <functional>
#include <string>

#include "reference/backend.h"

namespace rbx {

/// How long one library call may take before it is abandoned (s). Far above any legitimate
/// call (a contact query of two 8,192-vertex hulls takes milliseconds, the longest dynamics run
/// of the scene library seconds), with room for the sanitizer build's slowdown.
struct CallDeadlines {
  double contact_s = 30.0;    // one contact or distance query, its timing repeats included
  double dynamics_s = 600.0;  // one dynamics run of a whole scene
  double mass_s = 30.0;       // one library's mass properties of one hull
};

/// The outcome of an isolated call: its encoded answer, or why there is none.
struct CallOutcome {
  Status status = Status::Ok;  // Ok: `bytes` holds the answer; Error: died; Timeout: too slow
  std::string message;         // why, when not Ok (the signal and the library's last words)
  std::string bytes;           // the call's encoded answer, when Ok
  double elapsed_s = 0.0;      // wall time until the answer or the failure
};

/// Runs `call` (a call of backend `backend` that returns its answer encoded as bytes) so that
/// an abort, a crash or an overrun of `deadline_s` becomes a failed outcome naming the backend.
/// Inside a child of run_items_isolated it runs in that child, between "begins" and "ends";
/// elsewhere it forks a child of its own. `call` must catch its own exceptions.
CallOutcome isolated(const std::string& backend, double deadline_s,
                     const std::function<std::string()>& call);

/// Runs item(i) for i in [lo, hi) in supervised child processes and returns the results in
/// order (see the design note). An exception thrown by an item is rethrown here as
/// std::runtime_error with its message; a child that dies outside any isolated call (a fault
/// of rbx itself, not of a library) is rethrown likewise, naming the item and the signal.
/// `done(i)`, when given, is called in this process as item i's result arrives (progress).
std::vector<std::string> run_items_isolated(size_t lo, size_t hi,
                                            const std::function<std::string(size_t)>& item,
                                            const std::function<void(size_t)>& done = {});

/// True while this process is a child of run_items_isolated (its calls are supervised).
bool in_isolated_child();

/// A contact query and its run time (s), as an isolated call returns them.
struct TimedContact {
  ContactResult result;
  double runtime_s = 0.0;
};
/// A dynamics run and its run time (s).
struct TimedDynamics {
  DynamicsResult result;
  double runtime_s = 0.0;
};

/// `call` isolated as above; a failure becomes the result's status and message, with the time
/// until the failure as its run time.
TimedContact isolated_contact(const std::string& backend, double deadline_s,
                              const std::function<TimedContact()>& call);
/// Likewise for a whole dynamics run.
TimedDynamics isolated_dynamics(const std::string& backend, double deadline_s,
                                const std::function<TimedDynamics()>& call);
/// A distance query and its run time (s).
struct TimedDistance {
  DistanceResult result;
  double runtime_s = 0.0;
};
/// Likewise for a distance query.
TimedDistance isolated_distance(const std::string& backend, double deadline_s,
                                const std::function<TimedDistance()>& call);
/// A time-of-impact query and its run time (s).
struct TimedToi {
  ToiResult result;
  double runtime_s = 0.0;
};
/// Likewise for a time-of-impact query.
TimedToi isolated_toi(const std::string& backend, double deadline_s,
                      const std::function<TimedToi()>& call);
/// Likewise for a library's mass properties.
MassResult isolated_mass(const std::string& backend, double deadline_s,
                         const std::function<MassResult()>& call);

/// One contact query in a forked child of its own (kept for callers that isolate a single
/// library call, as FCL's INDEP distance); a timeout is status Timeout.
ContactResult run_isolated(const std::function<ContactResult()>& query, double timeout_s = 10.0);

}  // namespace rbx
