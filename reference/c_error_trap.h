// The error trap for C libraries that end the process on an error (MuJoCo's mju_error, ODE's
// dError/dDebug) unless a handler is installed, and whose handler must not return: the handler
// records the message and longjmps back to guarded(), which returns false instead.
//
// Design: one trap object per library and thread (thread_local in the adapter), plain char
// arrays because the handlers run inside the library's C frames and must not allocate or throw.
// guarded() is a template in this header so that setjmp sits in a frame that stays alive while
// the library runs. Nested guarded() calls restore the outer jump target.
#pragma once

#include <csetjmp>
#include <cstddef>

namespace rbx {

/// Error state of one C library on one thread.
struct CErrorTrap {
  static constexpr std::size_t kMessageSize = 512;
  std::jmp_buf* jump = nullptr;     // innermost guarded() on this thread, or none
  char error[kMessageSize] = {};    // the last error
  char warning[kMessageSize] = {};  // the first warning since clear_warning()
  long warning_count = 0;           // warnings counted (ODE counts its messages; resets it)

  /// Forgets the recorded warning (before a call whose warnings the caller reports).
  void clear_warning() { warning[0] = '\0'; }
  /// Whether a warning was recorded since clear_warning().
  bool has_warning() const { return warning[0] != '\0'; }
};

/// printf into a trap's message buffer (truncated to fit; no allocation).
void trap_printf(char (&buffer)[CErrorTrap::kMessageSize], const char* format, ...)
    __attribute__((format(printf, 2, 3)));

/// From an error handler: jumps back to the innermost guarded() of `trap`. Outside one there is
/// no safe place to return to, so it prints `outside_format` (one "%s": the recorded error) to
/// stderr and aborts, as the library itself would end the process.
[[noreturn]] void trap_jump_or_abort(CErrorTrap& trap, const char* outside_format);

/// Runs f(); returns false (message in trap.error) when the library's error handler called
/// trap_jump_or_abort during it. f must own no object with a non-trivial destructor: the
/// longjmp skips its frame.
template <class F>
bool guarded(CErrorTrap& trap, F&& f) {
  std::jmp_buf env;
  std::jmp_buf* const outer = trap.jump;
  trap.jump = &env;
  if (setjmp(env) != 0) {
    trap.jump = outer;
    return false;
  }
  f();
  trap.jump = outer;
  return true;
}

}  // namespace rbx
