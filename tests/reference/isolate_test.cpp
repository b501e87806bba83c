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

#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::same_bits;

// Wall time (s) of one call.
template <class F>
double seconds_of(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// True when the two doubles have the same bits (NaN payloads and the sign of zero included).

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
  EXPECT_EQ(r.status, Status::Timeout);
  EXPECT_NE(r.message.find("timed out"), std::string::npos) << r.message;
  // Not before the deadline; and well before the child's own end (never): 5 s covers a fork,
  // the 50 ms polling of the call state, a SIGKILL and a reap on a loaded 2-core machine.
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
  EXPECT_EQ(r.status, Status::Timeout);
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

// -- blocks of items (run_items_isolated, what ParallelRun::map runs) --------------------------

// A contact query of backend `name` that answers at once with one contact of depth `depth`.
std::string answer_item(const std::string& name, double depth) {
  const TimedContact t = isolated_contact(name, 5.0, [&] {
    return TimedContact{{Status::Ok, "", {ContactPoint{Vec3::Zero(), Vec3::UnitZ(), depth, "x"}}},
                        0.0};
  });
  return std::string(to_string(t.result.status)) + "|" + t.result.message + "|" +
         (t.result.contacts.empty() ? "" : std::to_string(t.result.contacts[0].depth));
}

TEST(RunItemsIsolated, AnEndlessQueryTimesOutAndTheOtherItemsGoOn) {
  // Item 2's "library" never returns. Its backend becomes `timeout` for that item; the items
  // before and after it, and another backend in the same item, answer as usual.
  const double deadline_s = 0.5;
  std::vector<size_t> done;
  std::vector<std::string> out;
  const double elapsed = seconds_of([&] {
    out = run_items_isolated(
        0, 5,
        [&](size_t i) {
          std::string s = answer_item("good", static_cast<double>(i));
          if (i == 2) {
            const TimedContact t = isolated_contact("endless", deadline_s, []() -> TimedContact {
              for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
            });
            s += "/" + std::string(to_string(t.result.status)) + "|" + t.result.message;
          }
          return s;
        },
        [&](size_t i) { done.push_back(i); });
  });
  ASSERT_EQ(out.size(), 5u);
  for (size_t i = 0; i < 5; ++i)
    EXPECT_EQ(out[i].rfind("ok||" + std::to_string(static_cast<double>(i)), 0), 0u) << out[i];
  EXPECT_NE(out[2].find("/timeout|no answer within the deadline"), std::string::npos) << out[2];
  EXPECT_EQ(done, (std::vector<size_t>{0, 1, 2, 3, 4}));
  // One deadline, not two: the second child answers the known failure at once.
  EXPECT_GE(elapsed, deadline_s);
  EXPECT_LT(elapsed, deadline_s + 5.0);
  expect_no_child_left();
}

TEST(RunItemsIsolated, AnAbortFailsThatBackendInThatItemOnly) {
  // A failed assertion prints its line and aborts: the backend's error names the signal and
  // quotes the line; every later call of that backend in the item gets the same answer without
  // running; the next item runs it again.
  const std::vector<std::string> out = run_items_isolated(0, 3, [](size_t i) {
    std::string s;
    for (int call = 0; call < 2; ++call) {
      const TimedContact t = isolated_contact("fragile", 5.0, [i]() -> TimedContact {
        if (i == 1) {
          std::fprintf(stderr, "fragile.h:12: check: Assertion `ok' failed.\n");
          std::abort();
        }
        return {};
      });
      s += std::string(to_string(t.result.status)) + "|" + t.result.message + "#";
    }
    return s + answer_item("sturdy", 1.0);
  });
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0], "ok|#ok|#ok||1.000000");
  EXPECT_EQ(out[2], "ok|#ok|#ok||1.000000");
  EXPECT_NE(
      out[1].find(std::string("error|the library call died with signal ") + strsignal(SIGABRT)),
      std::string::npos)
      << out[1];
  EXPECT_NE(out[1].find("fragile.h:12: check: Assertion `ok' failed."), std::string::npos)
      << out[1];
  const size_t first = out[1].find('#');
  EXPECT_EQ(out[1].substr(0, first), out[1].substr(first + 1, first)) << out[1];
  EXPECT_NE(out[1].find("ok||1.000000"), std::string::npos) << out[1];
  expect_no_child_left();
}

TEST(RunItemsIsolated, AnItemsExceptionIsRethrownHere) {
  EXPECT_THROW(
      {
        try {
          run_items_isolated(0, 3, [](size_t i) -> std::string {
            if (i == 1) throw std::runtime_error("bad sample 1");
            return "fine";
          });
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), "bad sample 1");
          throw;
        }
      },
      std::runtime_error);
  expect_no_child_left();
}

TEST(RunItemsIsolated, ADeathOutsideAnyLibraryCallIsRbxsOwnFault) {
  // Not a library's: nothing to blame and no call to answer for, so the map fails loudly.
  try {
    run_items_isolated(0, 2, [](size_t i) -> std::string {
      if (i == 1) raise(SIGKILL);
      return "fine";
    });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("outside any library call"), std::string::npos)
        << e.what();
  }
  expect_no_child_left();
}

TEST(RunItemsIsolated, ResultsAreTheItemsOwnBytesInOrder) {
  const std::vector<std::string> out = run_items_isolated(10, 14, [](size_t i) {
    return std::string("item ") + std::to_string(i) + std::string(1, '\0') + "end";
  });
  ASSERT_EQ(out.size(), 4u);
  for (size_t i = 0; i < 4; ++i)
    EXPECT_EQ(out[i], "item " + std::to_string(10 + i) + std::string(1, '\0') + "end");
  expect_no_child_left();
}

TEST(IsolatedDynamics, DartsAssertionOnANonFiniteStateIsItsError) {
  // Debian builds DART 6.12 with its assertions on: a NaN velocity fails one in BodyNode and
  // aborts. Isolated, as every library call in rbx's runs is, that is the backend's error naming
  // the signal, and this process goes on.
  for (const char* name : {"dart", "dart-hull"}) {
    WorldDefinition s;
    s.sim.duration = 0.01;
    BodySpec a;
    a.name = "A";
    a.shape = std::make_shared<const ConvexPolyhedron>(make_box(Vec3::Ones()));
    a.velocity = Vec3(std::nan(""), 0, 0);
    s.bodies = {a};
    const Backend* backend = find_backend(name);
    ASSERT_NE(backend, nullptr) << name;
    const TimedDynamics r = isolated_dynamics(name, 30.0, [&] {
      return TimedDynamics{backend->dynamics(s, {}), 0.0};
    });
    EXPECT_EQ(r.result.status, Status::Error) << name;
    EXPECT_NE(r.result.message.find("Aborted"), std::string::npos) << r.result.message;
  }
}

TEST(IsolatedDynamics, AWholeRunComesBackIntact) {
  // Every field of a dynamics result crosses the process boundary bit for bit.
  DynamicsResult sent;
  sent.message = "note";
  CollisionEvent e;
  e.time = 0.1 + 0.2;
  e.step = 42;
  e.body_a = "A";
  e.body_b = "B";
  e.contact = ContactPoint{Vec3(1.0 / 3, 2, 3), Vec3(0, 0, -1), 1e-310, "edge"};
  e.impulse = 2.25;
  sent.events = {e, e};
  BodyFinal f;
  f.name = "A";
  f.position = Vec3(1, 2, 3);
  f.orientation = Quat(0.5, 0.5, -0.5, 0.5);
  f.velocity = Vec3(-0.0, 1e300, 7);
  f.angular_velocity = Vec3(0.1, 0.2, 0.3);
  sent.finals = {f};
  sent.samples = {StateSample{0.5, {f, f}}};
  sent.first_impulse.seen = true;
  sent.first_impulse.body_a = "A";
  sent.first_impulse.step = 3;
  sent.first_impulse.contact_points = 4;
  sent.first_impulse.entry_phase = 0.7;
  const TimedDynamics got = isolated_dynamics("lib", 5.0, [&] { return TimedDynamics{sent, 1.5}; });
  ASSERT_EQ(got.result.status, Status::Ok) << got.result.message;
  EXPECT_EQ(got.runtime_s, 1.5);
  EXPECT_EQ(got.result.message, "note");
  ASSERT_EQ(got.result.events.size(), 2u);
  EXPECT_TRUE(same_bits(got.result.events[1].time, e.time));
  EXPECT_EQ(got.result.events[1].step, 42);
  EXPECT_TRUE(same_bits(got.result.events[1].contact.depth, 1e-310));
  EXPECT_EQ(got.result.events[1].contact.feature, "edge");
  ASSERT_EQ(got.result.finals.size(), 1u);
  EXPECT_TRUE(same_bits(got.result.finals[0].velocity.x(), -0.0));
  EXPECT_EQ(got.result.finals[0].orientation.coeffs(), f.orientation.coeffs());
  ASSERT_EQ(got.result.samples.size(), 1u);
  EXPECT_EQ(got.result.samples[0].bodies.size(), 2u);
  EXPECT_TRUE(got.result.first_impulse.seen);
  EXPECT_EQ(got.result.first_impulse.contact_points, 4);
  EXPECT_EQ(got.result.first_impulse.entry_phase, 0.7);
  expect_no_child_left();
}

}  // namespace
}  // namespace rbx
