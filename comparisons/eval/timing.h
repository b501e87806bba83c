// How rbx times a call, the way benchmark libraries do, so that a run time can be quoted.
//
// Design: the answer a backend gives comes from its first call, which is also timed alone and
// reported apart as the cold call (a fresh process, empty caches, first allocations). Timing is a
// separate pass over calls that already answered: each subject is warmed up once, its calls per
// round are chosen so that one round lasts well above the clock's resolution, and then rounds
// are run in turn, one round of every subject per turn, the starting subject rotating, until
// each subject has its minimum total time and its minimum count of rounds. Interleaving puts a
// passing load of the machine on every subject of the same inputs alike, so ratios between them
// hold better than their absolute times. Each round of a library is one isolated call
// (reference/isolate.h), made inside one supervised child process, so a library that aborts
// while being timed loses its timing, not the run. A timing is the median of the rounds' times
// per call, with its 25-75 % range and the count of calls.
#pragma once

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace rbx {

/// A call's run time: the median per call over the timed rounds, its spread and its counts.
struct Timing {
  double median_s = 0.0;  // per call, median over the rounds
  double q25_s = 0.0;     // 25 % quantile of the rounds' per-call times
  double q75_s = 0.0;     // 75 % quantile
  long calls = 0;         // calls timed (rounds x calls per round), the warm-up excluded
  int rounds = 0;         // 0: not timed (the call failed, or failed while being timed)
  double cold_s = 0.0;    // the first call alone, as it answered: reported apart, never mixed in
  /// The 25-75 % range relative to the median (0 when untimed).
  double spread() const { return median_s > 0 ? (q75_s - q25_s) / median_s : 0.0; }
  /// One call timed alone (a whole dynamics run): the median, the quartiles and the cold call.
  static Timing once(double s) { return {s, s, s, 1, 1, s}; }
};

/// How long to time: at least `min_time_s` of timed calls and `min_rounds` rounds per subject;
/// a subject whose single call is slow stops at `min_rounds_slow` rounds once it has spent
/// `slow_factor` times the minimum (a 100 ms query is not repeated for seconds).
struct TimingPlan {
  double min_time_s = 0.01;
  int min_rounds = 7;
  int min_rounds_slow = 3;
  double slow_factor = 5.0;
  int max_rounds = 1000;
  double round_floor_s = 2e-5;  // a round lasts at least this (steady_clock reads in ~20 ns)
  /// The caller has already run every subject once (its warm-up): no warm-up call here, and the
  /// call that sizes the rounds counts as the first round when it alone lasts min_time_s (a
  /// query of seconds is not run twice more before its rounds; that round then precedes the
  /// first turn).
  bool warmed_up = false;
};

/// One subject to time: a call that has already answered, and what isolates it.
struct TimedSubject {
  std::string backend;   // names the call in a failure
  bool library = false;  // a library's call: each round isolated
  std::function<void()> call;
  double deadline_s = 30.0;  // per round, as the call's own deadline
  /// Untimed work before every call (moving a crowd between broad-phase steps); empty: none.
  /// With it each call is timed alone and the round's time is the sum.
  std::function<void()> set_up = {};
};

/// One subject's rounds as timed: the time per call of each round, in the order run. Round k of
/// every subject ran in the same turn, so rounds of the same index are paired in time.
struct Rounds {
  std::vector<double> per_call_s;  // empty: the subject failed (or threw) while being timed
  long per_round = 0;              // calls in each round
};

/// The timing of a subject's rounds: median, quartiles and counts (cold_s left 0).
Timing timing_of(const Rounds& r);

/// A ratio between two subjects timed together, round by round: the median and 25-75 % range
/// of a[k] / b[k] over the rounds both have. NaN (and rounds 0) when they share none.
struct RatioSpread {
  double median = NAN, q25 = NAN, q75 = NAN;
  int rounds = 0;
};
RatioSpread paired_ratio(const std::vector<double>& a, const std::vector<double>& b);

/// The rounds themselves, timed in this process (for subjects that are not libraries, or
/// inside a supervised child): what time_interleaved summarises.
std::vector<Rounds> time_rounds(const std::vector<TimedSubject>& subjects,
                                const TimingPlan& plan = {});

/// Times the subjects interleaved (see the design note); one Timing per subject, in order, with
/// cold_s left 0 for the caller to fill from the answering call. A subject that throws or fails
/// while being timed gets rounds = 0. Outside a supervised child, the whole pass runs in one.
std::vector<Timing> time_interleaved(const std::vector<TimedSubject>& subjects,
                                     const TimingPlan& plan = {});

/// time_interleaved's Timing of each subject written to `into` (one per subject, in order), each
/// keeping the cold_s it holds: the answering call's, which the caller timed.
void time_into(const std::vector<TimedSubject>& subjects, const std::vector<Timing*>& into,
               const TimingPlan& plan = {});

}  // namespace rbx
