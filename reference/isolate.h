// Running a library call where an abort or a crash cannot take rbx down.
#pragma once

#include <functional>

#include "reference/backend.h"

namespace rbx {

/// Runs `query` in a forked child process and returns its result. If the child aborts (a failed
/// assertion), crashes or exceeds `timeout_s`, the result is status Error naming the signal.
/// Costs a fork per call: use it only for calls known to abort (FCL GST_INDEP distance).
ContactResult run_isolated(const std::function<ContactResult()>& query, double timeout_s = 10.0);

}  // namespace rbx
