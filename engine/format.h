// Numbers as text: the one place in rbx that turns a double into characters, for terminal
// tables, reports, error messages, benchmark pages and the model text handed to other libraries
// (MuJoCo's MJCF). Every writer chooses its style by parameters, so each keeps its exact output.
#pragma once

#include <string>

#include "engine/math.h"

namespace rbx {

/// How format_number writes a double.
struct NumberFormat {
  /// Significant digits, as printf's "%.*g"; 0: the shortest text that reads back as the same
  /// double (at most 17 digits).
  int digits = 6;
  /// false: -0 is written "0"; true: "-0", as printf and std::ostream write it.
  bool signed_zero = false;
  /// Text for NaN and both infinities; nullptr: "nan", "inf" and "-inf".
  const char* non_finite = nullptr;
  /// With digits = 0: values of magnitude in [1, 1e6) keep every integer digit ("604800", not
  /// "6.048e+05"), which reads better in messages about scene values.
  bool integer_digits = false;
  /// With digits = 0: magnitudes in [1e-5, 1e15) take as many digits as they need to be written
  /// without an exponent ("90", not "9e+01"), as a scene file reads best.
  bool plain_decimals = false;
};

/// `x` as text in the style `f`.
std::string format_number(double x, const NumberFormat& f);

/// `x` with `digits` significant digits ("%.*g"); "nan"/"inf"/"-inf" spelled out; no "-0".
std::string fmt_num(double x, int digits = 6);

/// "(x, y, z)" with fmt_num.
std::string fmt_vec(const Vec3& v, int digits = 4);

/// A duration given in ns, in the unit that reads best in a table: three significant digits and
/// "ns", "µs", "ms" or "s"; "—" when not finite.
std::string fmt_duration_ns(double ns);

}  // namespace rbx
