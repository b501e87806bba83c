// reference/c_error_trap.h on a stand-in for a C library's error handler (the MuJoCo and ODE
// tests drive the real ones: MujocoErrors.*, OdeDynamics.OdeErrorsBecomeStatusError).
#include "reference/c_error_trap.h"

#include <gtest/gtest.h>

#include <string>

namespace rbx {
namespace {

thread_local CErrorTrap t_test_trap;

// What a library's error handler does: record the message, then never return.
void library_error(const char* what, int code) {
  trap_printf(t_test_trap.error, "lib error %d: %s", code, what);
  trap_jump_or_abort(t_test_trap, "%s (outside a guarded call)\n");
}

TEST(CErrorTrap, AnErrorInsideGuardedReturnsFalseWithTheMessage) {
  int reached = 0;
  const bool ok = guarded(t_test_trap, [&] {
    reached = 1;
    library_error("bad pointer", 7);
    reached = 2;  // never: the handler jumped out
  });
  EXPECT_FALSE(ok);
  EXPECT_EQ(reached, 1);
  EXPECT_EQ(std::string(t_test_trap.error), "lib error 7: bad pointer");
  EXPECT_EQ(t_test_trap.jump, nullptr);  // the jump target is cleared on the way out
}

TEST(CErrorTrap, NestedGuardedCallsRestoreTheOuterTarget) {
  bool inner_ok = true;
  const bool outer_ok = guarded(t_test_trap, [&] {
    inner_ok = guarded(t_test_trap, [] { library_error("inner", 1); });
    library_error("outer", 2);  // lands in the outer call, not the finished inner one
  });
  EXPECT_FALSE(inner_ok);
  EXPECT_FALSE(outer_ok);
  EXPECT_EQ(std::string(t_test_trap.error), "lib error 2: outer");
}

TEST(CErrorTrap, WithoutAnErrorGuardedReturnsTrue) {
  int calls = 0;
  EXPECT_TRUE(guarded(t_test_trap, [&] { ++calls; }));
  EXPECT_EQ(calls, 1);
}

TEST(CErrorTrap, WarningsKeepTheFirstUntilCleared) {
  t_test_trap.clear_warning();
  EXPECT_FALSE(t_test_trap.has_warning());
  trap_printf(t_test_trap.warning, "%s", "first");
  EXPECT_TRUE(t_test_trap.has_warning());
  t_test_trap.clear_warning();
  EXPECT_FALSE(t_test_trap.has_warning());
}

TEST(CErrorTrapDeathTest, AnErrorOutsideGuardedAbortsWithTheMessage) {
  EXPECT_DEATH(library_error("no handler", 3),
               "lib error 3: no handler \\(outside a guarded call\\)");
}

TEST(CErrorTrap, LongMessagesAreTruncatedToTheBuffer) {
  const std::string long_text(2 * CErrorTrap::kMessageSize, 'x');
  trap_printf(t_test_trap.error, "%s", long_text.c_str());
  EXPECT_EQ(std::string(t_test_trap.error).size(), CErrorTrap::kMessageSize - 1);
}

}  // namespace
}  // namespace rbx
