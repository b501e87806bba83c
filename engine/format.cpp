#include "engine/format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace rbx {

std::string format_number(double x, const NumberFormat& f) {
  if (!std::isfinite(x)) {
    if (f.non_finite) return f.non_finite;
    if (std::isnan(x)) return "nan";
    return x > 0 ? "inf" : "-inf";
  }
  if (x == 0.0 && !f.signed_zero) x = 0.0;  // drops the sign of -0
  char buffer[64];
  int digits = f.digits;
  if (digits <= 0) {
    // Shortest: the fewest significant digits that read back as the same double.
    const double a = std::abs(x);
    const bool exponent_allowed = !f.plain_decimals || a < 1e-5 || a >= 1e15;
    for (digits = 1; digits < 17; ++digits) {
      std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
      if (std::strtod(buffer, nullptr) == x && (exponent_allowed || !std::strchr(buffer, 'e')))
        break;
    }
    if (f.integer_digits && a >= 1 && a < 1e6)
      digits = std::max(digits, 1 + static_cast<int>(std::log10(a)));
  }
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
  return buffer;
}

std::string fmt_num(double x, int digits) {
  NumberFormat f;
  f.digits = digits;
  return format_number(x, f);
}

std::string fmt_vec(const Vec3& v, int digits) {
  return "(" + fmt_num(v.x(), digits) + ", " + fmt_num(v.y(), digits) + ", " +
         fmt_num(v.z(), digits) + ")";
}

std::string fmt_duration_ns(double ns) {
  NumberFormat f;
  f.digits = 3;
  f.signed_zero = true;
  f.non_finite = "—";
  if (!std::isfinite(ns)) return f.non_finite;
  if (ns < 1e3) return format_number(ns, f) + " ns";
  if (ns < 1e6) return format_number(ns / 1e3, f) + " µs";
  if (ns < 1e9) return format_number(ns / 1e6, f) + " ms";
  return format_number(ns / 1e9, f) + " s";
}

}  // namespace rbx
