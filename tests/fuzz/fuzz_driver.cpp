// libFuzzer driver: one executable per target, the target chosen at compile time by
// RBX_FUZZ_TARGET (its entry function's name). A broken invariant or any exception the target
// does not allow becomes an abort, which libFuzzer records as a crash file.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <typeinfo>

#include "tests/fuzz/targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    rbx::fuzz::RBX_FUZZ_TARGET(data, size);
  } catch (const rbx::fuzz::InvariantViolation& e) {
    std::fprintf(stderr, "rbx fuzz: invariant violated: %s\n", e.what());
    std::abort();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rbx fuzz: unexpected exception %s: %s\n", typeid(e).name(), e.what());
    std::abort();
  }
  return 0;
}
