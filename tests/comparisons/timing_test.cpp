// How rbx times a call (comparisons/eval/timing.h): warmed up, rounds sized above the clock's
// resolution, subjects interleaved, a failing subject losing its timing and nothing else. No
// assertion here is a speed goal: the only times asserted are lower bounds a call cannot beat
// (it spins until its time has passed).
#include "comparisons/eval/timing.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace rbx {
namespace {

// Spins until `s` seconds have passed: a call that cannot take less.
void spin(double s) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(s);
  while (std::chrono::steady_clock::now() < until) {
  }
}

TEST(Timing, EveryRoundIsLongerThanTheClocksFloorAndEachSubjectGetsItsMinimum) {
  TimingPlan plan;
  plan.min_time_s = 0.004;
  int fast_calls = 0;
  const std::vector<Timing> t = time_interleaved(
      {{"fast", false, [&] { ++fast_calls; }}, {"slow", false, [] { spin(2e-5); }}}, plan);
  ASSERT_EQ(t.size(), 2u);
  for (const Timing& x : t) {
    EXPECT_GE(x.rounds, plan.min_rounds);
    EXPECT_LE(x.q25_s, x.median_s);
    EXPECT_LE(x.median_s, x.q75_s);
    EXPECT_EQ(x.calls % x.rounds, 0) << "every round makes the same number of calls";
  }
  // A call that does almost nothing is repeated within a round, so that a round is long enough
  // to time (round_floor_s); the warm-up and three sizing calls (the fastest sizes the rounds)
  // come before them.
  EXPECT_GT(t[0].calls / t[0].rounds, 1);
  EXPECT_EQ(fast_calls, t[0].calls + 4);
  EXPECT_GE(t[1].median_s, 2e-5);
  EXPECT_GE(t[1].q25_s, 2e-5);
  EXPECT_EQ(t[0].cold_s, 0.0) << "the cold call is the caller's: the one that answered";
}

TEST(Timing, SetUpRunsBeforeEveryCallOutsideTheClock) {
  // The set-up spins 1 ms and the call 20 µs: a round timed with its set-ups would give at
  // least 1 ms per call; timed without them, a call's median stays far below (the spin ends at
  // 20 µs; 500 µs leaves the scheduler a wide margin).
  TimingPlan plan;
  plan.min_time_s = 1e-6;
  plan.min_rounds = 5;
  plan.min_rounds_slow = 5;  // the rounds all count, however the time adds up
  int set_ups = 0, calls = 0;
  TimedSubject s{"moved", false, [&] {
                   ++calls;
                   spin(2e-5);
                 }};
  s.set_up = [&] {
    ++set_ups;
    spin(1e-3);
  };
  const std::vector<Rounds> r = time_rounds({s}, plan);
  ASSERT_EQ(r.size(), 1u);
  ASSERT_EQ(static_cast<int>(r[0].per_call_s.size()), plan.min_rounds);
  EXPECT_EQ(set_ups, calls) << "one set-up before every call";
  const Timing t = timing_of(r[0]);
  EXPECT_GE(t.median_s, 2e-5);
  EXPECT_LT(t.median_s, 5e-4);
}

TEST(Timing, AWarmedUpCallThatLastsTheMinimumTimeIsARoundItself) {
  // A call of 3 ms against a minimum time of 2 ms: after the caller's warm-up, the call that
  // sizes the rounds is the first round, so every call made is a call timed.
  for (bool warmed_up : {false, true}) {
    TimingPlan plan;
    plan.min_time_s = 2e-3;
    plan.min_rounds = 3;
    plan.warmed_up = warmed_up;
    int calls = 0;
    const std::vector<Rounds> r = time_rounds({{"slow", false,
                                                [&] {
                                                  ++calls;
                                                  spin(3e-3);
                                                }}},
                                              plan);
    ASSERT_EQ(r.size(), 1u);
    const int rounds = static_cast<int>(r[0].per_call_s.size());
    EXPECT_GE(rounds, plan.min_rounds);
    EXPECT_EQ(r[0].per_round, 1);
    EXPECT_EQ(calls, warmed_up ? rounds : rounds + 2) << "warmed up: " << warmed_up;
    for (double t : r[0].per_call_s) EXPECT_GE(t, 3e-3);
  }
}

TEST(Timing, OneSlowSizingCallDoesNotMakeTheRoundsShort) {
  // A subject of 5 µs calls whose first call after the warm-up takes 2 ms (a page fault, a cache
  // refilled): sized from that call alone, its rounds would be ~2 calls long; the fastest of three
  // sizes them near the target round (the larger of 20 µs and min_time / 14).
  TimingPlan plan;
  plan.min_time_s = 7e-3;  // target round: 0.5 ms, about 100 calls of 5 µs
  plan.min_rounds = 7;
  int calls = 0;
  const std::vector<Rounds> r = time_rounds({{"hiccup", false,
                                              [&] {
                                                ++calls;
                                                spin(calls == 2 ? 2e-3 : 5e-6);
                                              }}},
                                            plan);
  ASSERT_EQ(r.size(), 1u);
  // 0.5 ms / 5 µs = 100 calls; the clock and the loop add a little to each call.
  // Sized from the slow call alone it would be 1; a loaded machine may stretch a 5 µs call, so
  // the bound is loose (a quarter of the ideal 100).
  EXPECT_GE(r[0].per_round, 25) << "sized from the slow call alone";
  EXPECT_LE(r[0].per_round, 100);
}

TEST(Timing, SubjectsTakeTurnsRoundByRound) {
  TimingPlan plan;
  plan.min_time_s = 1e-6;  // every subject stops at min_rounds, whatever the load: one call a round
  std::string order;
  auto call = [&](char who) {
    return [&order, who] {
      order += who;
      spin(1e-4);
    };
  };
  const std::vector<Timing> t =
      time_interleaved({{"a", false, call('a')}, {"b", false, call('b')}}, plan);
  ASSERT_EQ(t[0].rounds, t[1].rounds);
  // After the warm-up and sizing calls (aabb), one round each per turn, the first of a turn
  // rotating: ab ba ab ..., never three rounds of one subject in a row.
  ASSERT_EQ(order.substr(0, 4), "aabb");
  const std::string rounds = order.substr(4);
  EXPECT_EQ(rounds.size(), static_cast<size_t>(t[0].calls + t[1].calls));
  EXPECT_EQ(rounds.substr(0, 4), "abba");
  EXPECT_EQ(rounds.find("aaa"), std::string::npos) << rounds;
  EXPECT_EQ(rounds.find("bbb"), std::string::npos) << rounds;
}

TEST(Timing, ASubjectThatThrowsWhileTimedLosesItsTimingOnly) {
  int calls = 0;
  const std::vector<Timing> t = time_interleaved({{"flaky", false,
                                                   [&] {
                                                     if (++calls > 3)
                                                       throw std::runtime_error("gave up");
                                                   }},
                                                  {"steady", false, [] { spin(1e-6); }}});
  EXPECT_EQ(t[0].rounds, 0);
  EXPECT_EQ(t[0].median_s, 0.0);
  EXPECT_GE(t[1].rounds, TimingPlan{}.min_rounds);
  EXPECT_GE(t[1].median_s, 1e-6);
}

// A library that aborts while being timed (it answered once, then died on a repeat): its rounds
// run isolated in a supervised child, so it loses its timing and the other library keeps its.
TEST(Timing, ALibraryThatAbortsWhileTimedLosesItsTimingNotTheRun) {
  TimingPlan plan;
  plan.min_time_s = 0.002;
  int calls = 0;  // counted in the child
  const std::vector<Timing> t = time_interleaved({{"steady", true, [] { spin(1e-6); }},
                                                  {"dies", true,
                                                   [&] {
                                                     if (++calls > 5) std::abort();
                                                   }}},
                                                 plan);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_GE(t[0].rounds, plan.min_rounds);
  EXPECT_GE(t[0].median_s, 1e-6);
  EXPECT_EQ(t[1].rounds, 0);
}

}  // namespace
}  // namespace rbx
