// run_isolated (reference/isolate.h): a library call that aborts, throws, hangs or dies quietly
// becomes status Error with a message that says which, and a normal call's result comes back
// intact, bit for bit, through the pipe from the child process.
#include "reference/isolate.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

namespace rbx {
namespace {

// Wall time (s) of one call.
template <class F>
double seconds_of(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// True when the two doubles have the same bits (NaN payloads and the sign of zero included).
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// After run_isolated returns, its child has been reaped: this process has no child left.
void expect_no_child_left() {
  errno = 0;
  EXPECT_EQ(waitpid(-1, nullptr, WNOHANG), -1);
  EXPECT_EQ(errno, ECHILD) << "run_isolated left a child process (a zombie or a runaway)";
}

TEST(RunIsolated, AbortBecomesErrorNamingTheSignal) {
  // A failed assertion in a library (FCL's GST_INDEP distance) ends in abort(): SIGABRT.
  const ContactResult r = run_isolated([]() -> ContactResult { std::abort(); });
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find(strsignal(SIGABRT)), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("signal"), std::string::npos) << r.message;
  EXPECT_TRUE(r.contacts.empty());
  expect_no_child_left();
}

TEST(RunIsolated, OtherFatalSignalIsNamedToo) {
  // Not every sanitizer runtime lets SIGSEGV through (ASan turns it into a report and exit 1),
  // so the child raises a signal nothing intercepts: SIGKILL, what the OOM killer sends.
  const ContactResult r = run_isolated([]() -> ContactResult {
    raise(SIGKILL);
    return {};
  });
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find(strsignal(SIGKILL)), std::string::npos) << r.message;
  expect_no_child_left();
}

TEST(RunIsolated, ExceptionBecomesErrorWithItsMessage) {
  const ContactResult r = run_isolated([]() -> ContactResult {
    throw std::runtime_error("GJK did not converge after 128 iterations");
  });
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_EQ(r.message, "GJK did not converge after 128 iterations");
  EXPECT_TRUE(r.contacts.empty());
  expect_no_child_left();
}

TEST(RunIsolated, NonStandardExceptionIsAnErrorAndTheChildStops) {
  // `throw 42` is no std::exception. Before the fix in isolate.cpp it escaped run_isolated in
  // the child, which then ran on as a second copy of the caller (here: the rest of this test
  // suite, twice). The child must always end inside run_isolated: the pid check proves that the
  // code after the call runs in the parent only.
  const pid_t parent = getpid();
  const ContactResult r = run_isolated([]() -> ContactResult { throw 42; });
  if (getpid() != parent) _exit(99);  // a child got here: fail loudly (the parent sees no result)
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find("non-standard exception"), std::string::npos) << r.message;
  expect_no_child_left();
}

TEST(RunIsolated, HangIsKilledAfterTheTimeout) {
  const double timeout_s = 0.5;
  ContactResult r;
  const double elapsed = seconds_of([&] {
    r = run_isolated(
        []() -> ContactResult {
          for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
        },
        timeout_s);
  });
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find("timed out"), std::string::npos) << r.message;
  // Not before the deadline (the parent polls until then); and well before the child's own
  // end (never): 5 s covers a fork, a SIGKILL and a reap on a loaded 2-core machine.
  EXPECT_GE(elapsed, timeout_s);
  EXPECT_LT(elapsed, timeout_s + 5.0);
  expect_no_child_left();
}

TEST(RunIsolated, AnswerAfterTheDeadlineIsDiscarded) {
  // A query that would answer, but too late: the deadline wins, and the late answer is never
  // taken for a result.
  const ContactResult r = run_isolated(
      []() -> ContactResult {
        std::this_thread::sleep_for(std::chrono::seconds(30));
        return {Status::Ok, "late", {}};
      },
      0.3);
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find("timed out"), std::string::npos) << r.message;
  expect_no_child_left();
}

TEST(RunIsolated, ChildExitingWithoutAnswerIsAnError) {
  // A library that calls exit() (ODE's default error handler does) leaves no result.
  const ContactResult r = run_isolated([]() -> ContactResult { _exit(3); });
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find("no result"), std::string::npos) << r.message;
  expect_no_child_left();
}

TEST(RunIsolated, NormalResultComesBackIntact) {
  // Values chosen to catch any lossy encoding: non-terminating binary fractions, a subnormal,
  // negative zero, the largest double, a NaN, and strings with a NUL byte and UTF-8.
  ContactPoint c1;
  c1.point = Vec3(0.1, -1.0 / 3.0, 1e-310);
  c1.normal = Vec3(-0.0, 0.6, 0.8);
  c1.depth = std::numeric_limits<double>::max();
  c1.feature = std::string("face\0edge", 9);
  ContactPoint c2;
  c2.point = Vec3(std::nan(""), 2.5, -7.25);
  c2.normal = Vec3(0, 0, 1);
  c2.depth = 0.0;
  c2.feature = "sommet \xC3\xA9";
  const ContactResult sent{Status::Ok, "note: two contacts", {c1, c2}};

  const ContactResult r = run_isolated([&] { return sent; });
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  EXPECT_EQ(r.message, sent.message);
  ASSERT_EQ(r.contacts.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const ContactPoint& got = r.contacts[i];
    const ContactPoint& want = sent.contacts[i];
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(same_bits(got.point[k], want.point[k])) << "contact " << i << " point " << k;
      EXPECT_TRUE(same_bits(got.normal[k], want.normal[k])) << "contact " << i << " normal " << k;
    }
    EXPECT_TRUE(same_bits(got.depth, want.depth)) << "contact " << i;
    EXPECT_EQ(got.feature, want.feature) << "contact " << i;
  }
  expect_no_child_left();
}

TEST(RunIsolated, StatusAndEmptyResultsPassThrough) {
  // "Not touching" (Ok, no contacts) and a backend's own Unsupported are results, not failures.
  const ContactResult apart = run_isolated([] { return ContactResult{}; });
  EXPECT_EQ(apart.status, Status::Ok);
  EXPECT_TRUE(apart.message.empty());
  EXPECT_TRUE(apart.contacts.empty());
  const ContactResult unsupported = run_isolated([] {
    return ContactResult{Status::Unsupported, "no prisms", {}};
  });
  EXPECT_EQ(unsupported.status, Status::Unsupported);
  EXPECT_EQ(unsupported.message, "no prisms");
  expect_no_child_left();
}

TEST(RunIsolated, ResultLargerThanAPipeBufferArrives) {
  // A Linux pipe holds 64 KiB; 1000 contacts of 7 doubles plus a 200 KB message need several
  // reads while the child still writes.
  ContactResult sent{Status::Ok, std::string(200000, 'x'), {}};
  for (int i = 0; i < 1000; ++i) {
    ContactPoint c;
    c.point = Vec3(i, 0.5 * i, -i);
    c.depth = 1e-3 * i;
    c.feature = "vertex";
    sent.contacts.push_back(c);
  }
  const ContactResult r = run_isolated([&] { return sent; });
  ASSERT_EQ(r.status, Status::Ok) << r.message.substr(0, 200);
  EXPECT_EQ(r.message, sent.message);
  ASSERT_EQ(r.contacts.size(), sent.contacts.size());
  // Index 999: the last contact, all of whose bytes came after the first pipe-full.
  EXPECT_EQ(r.contacts[999].point, Vec3(999, 499.5, -999));
  EXPECT_EQ(r.contacts[999].depth, sent.contacts[999].depth);
  expect_no_child_left();
}

TEST(RunIsolated, ChildCannotChangeTheParentsState) {
  // The query runs in another process: what it writes to memory stays there. (The reason an
  // abort cannot take rbx down is the same separation.)
  int counter = 0;
  const ContactResult r = run_isolated([&] {
    counter = 7;
    return ContactResult{};
  });
  EXPECT_EQ(r.status, Status::Ok);
  EXPECT_EQ(counter, 0);
  expect_no_child_left();
}

}  // namespace
}  // namespace rbx
