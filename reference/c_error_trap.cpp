#include "reference/c_error_trap.h"

#include <cstdarg>
#include <cstdio>
#include <cstdlib>

namespace rbx {

void trap_printf(char (&buffer)[CErrorTrap::kMessageSize], const char* format, ...) {
  va_list ap;
  va_start(ap, format);
  std::vsnprintf(buffer, sizeof buffer, format, ap);
  va_end(ap);
}

void trap_jump_or_abort(CErrorTrap& trap, const char* outside_format) {
  if (trap.jump) std::longjmp(*trap.jump, 1);
  std::fprintf(stderr, outside_format, trap.error);
  std::abort();
}

}  // namespace rbx
