#include "comparisons/eval/timing.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include "comparisons/eval/json_io.h"
#include "comparisons/eval/metrics.h"
#include "reference/isolate.h"
#include "reference/result_codec.h"

namespace rbx {
namespace {

struct Progress {
  Rounds rounds;
  double total_s = 0.0;
  bool failed = false;
  bool done = false;
};

// Runs `n` calls of `s` in a row and returns their time, or a negative number when a call threw
// or the isolated round failed.
double timed_round(const TimedSubject& s, long n) {
  double t = -1.0;
  auto round = [&] {
    try {
      if (s.set_up) {
        t = 0.0;
        for (long k = 0; k < n; ++k) {
          s.set_up();
          Stopwatch clock;
          s.call();
          t += clock.seconds();
        }
      } else {
        Stopwatch clock;
        for (long k = 0; k < n; ++k) s.call();
        t = clock.seconds();
      }
    } catch (const std::exception&) {
      t = -1.0;
    }
    return std::string();
  };
  if (!s.library) {
    round();
    return t;
  }
  return isolated(s.backend, s.deadline_s, round).status == Status::Ok ? t : -1.0;
}

bool finished(const Progress& p, const TimingPlan& plan) {
  const int rounds = static_cast<int>(p.rounds.per_call_s.size());
  return (rounds >= plan.min_rounds && p.total_s >= plan.min_time_s) ||
         (rounds >= plan.min_rounds_slow && p.total_s >= plan.slow_factor * plan.min_time_s) ||
         rounds >= plan.max_rounds;
}

}  // namespace

std::vector<Rounds> time_rounds(const std::vector<TimedSubject>& subjects, const TimingPlan& plan) {
  const size_t n = subjects.size();
  std::vector<Progress> at(n);
  // A round long enough that the clock's resolution and overhead vanish, short enough that
  // every subject gets its minimum count of rounds within its minimum time.
  const double target_s =
      std::max(plan.round_floor_s, plan.min_time_s / (2.0 * std::max(plan.min_rounds, 1)));
  for (size_t i = 0; i < n; ++i) {
    // The warm-up call, untimed (unless the caller made it), then one call to size the rounds.
    const double warm = plan.warmed_up ? 0.0 : timed_round(subjects[i], 1);
    double one = warm < 0 ? warm : timed_round(subjects[i], 1);
    // One call can be slow for a reason of its own (a page fault, caches refilled after the
    // warm-up) and would size every round a few calls long: each round would then time mostly
    // what the other subjects' turns evicted. For calls shorter than the minimum time (two more
    // cost at most twice that), the fastest of three sizes the rounds.
    for (int k = 0; k < 2 && one >= 0 && one < plan.min_time_s; ++k) {
      const double again = timed_round(subjects[i], 1);
      one = again < 0 ? again : std::min(one, again);
    }
    if (one < 0) {
      at[i].failed = true;
      continue;
    }
    at[i].rounds.per_round =
        static_cast<long>(std::clamp(std::ceil(target_s / std::max(one, 1e-9)), 1.0, 1e7));
    // A call that alone lasts the minimum time is a round of its own: after the caller's
    // warm-up, it is not made twice more before its rounds.
    if (plan.warmed_up && one >= plan.min_time_s) {
      at[i].rounds.per_call_s.push_back(one);
      at[i].total_s += one;
      at[i].done = finished(at[i], plan);
    }
  }
  for (size_t turn = 0;; ++turn) {
    bool any = false;
    for (size_t j = 0; j < n; ++j) {
      Progress& p = at[(turn + j) % n];
      if (p.failed || p.done) continue;
      any = true;
      const double t = timed_round(subjects[(turn + j) % n], p.rounds.per_round);
      if (t < 0) {
        p.failed = true;
        continue;
      }
      p.rounds.per_call_s.push_back(t / static_cast<double>(p.rounds.per_round));
      p.total_s += t;
      p.done = finished(p, plan);
    }
    if (!any) break;
  }
  std::vector<Rounds> out(n);
  for (size_t i = 0; i < n; ++i)
    if (!at[i].failed) out[i] = at[i].rounds;
  return out;
}

Timing timing_of(const Rounds& r) {
  Timing t;
  if (r.per_call_s.empty()) return t;
  std::vector<double> v = r.per_call_s;
  std::sort(v.begin(), v.end());
  t.median_s = sorted_quantile(v, 0.5);
  t.q25_s = sorted_quantile(v, 0.25);
  t.q75_s = sorted_quantile(v, 0.75);
  t.rounds = static_cast<int>(v.size());
  t.calls = r.per_round * t.rounds;
  return t;
}

RatioSpread paired_ratio(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> q;
  for (size_t k = 0; k < std::min(a.size(), b.size()); ++k)
    if (b[k] != 0.0 && std::isfinite(a[k] / b[k])) q.push_back(a[k] / b[k]);
  RatioSpread r;
  if (q.empty()) return r;
  std::sort(q.begin(), q.end());
  r.median = sorted_quantile(q, 0.5);
  r.q25 = sorted_quantile(q, 0.25);
  r.q75 = sorted_quantile(q, 0.75);
  r.rounds = static_cast<int>(q.size());
  return r;
}

std::vector<Timing> time_interleaved(const std::vector<TimedSubject>& subjects,
                                     const TimingPlan& plan) {
  const bool libraries = std::any_of(subjects.begin(), subjects.end(),
                                     [](const TimedSubject& s) { return s.library; });
  auto here = [&] {
    std::vector<Timing> t;
    for (const Rounds& r : time_rounds(subjects, plan)) t.push_back(timing_of(r));
    return t;
  };
  if (!libraries || in_isolated_child()) return here();
  // Every round of a library is an isolated call: inside one supervised child these cost
  // nothing, where each alone would be a fork.
  const std::vector<std::string> bytes = run_items_isolated(0, 1, [&](size_t) {
    ByteWriter w;
    for (const Timing& t : here()) w.io(t.median_s, t.q25_s, t.q75_s, t.calls, t.rounds);
    return w.str();
  });
  std::vector<Timing> out(subjects.size());
  ByteReader in(bytes.at(0));
  for (Timing& t : out) in.io(t.median_s, t.q25_s, t.q75_s, t.calls, t.rounds);
  return out;
}

void time_into(const std::vector<TimedSubject>& subjects, const std::vector<Timing*>& into,
               const TimingPlan& plan) {
  const std::vector<Timing> t = time_interleaved(subjects, plan);
  for (size_t i = 0; i < into.size() && i < t.size(); ++i) {
    const double cold = into[i]->cold_s;
    *into[i] = t[i];
    into[i]->cold_s = cold;
  }
}

}  // namespace rbx
