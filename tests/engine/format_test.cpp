// engine/format.h: every writer's style, with outputs that follow from printf's "%.*g".
#include "engine/format.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>

namespace rbx {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

TEST(FormatNumber, TableStyleHasSignificantDigitsAndNoNegativeZero) {
  EXPECT_EQ(fmt_num(3.14159265), "3.14159");
  EXPECT_EQ(fmt_num(3.14159265, 3), "3.14");
  EXPECT_EQ(fmt_num(1234567.0), "1.23457e+06");
  EXPECT_EQ(fmt_num(-0.0), "0");
  EXPECT_EQ(fmt_num(kNan), "nan");
  EXPECT_EQ(fmt_num(-kInf), "-inf");
  EXPECT_EQ(fmt_vec(Vec3(1.0, -0.5, 1.0 / 3.0)), "(1, -0.5, 0.3333)");
}

TEST(FormatNumber, ShortestReadsBackExactly) {
  NumberFormat f;
  f.digits = 0;
  EXPECT_EQ(format_number(0.1, f), "0.1");
  EXPECT_EQ(format_number(1e-5, f), "1e-05");
  EXPECT_EQ(format_number(604800.0, f), "6.048e+05");
  for (double x : {0.1, 1.0 / 3.0, 2.0 / 7.0 * 1e-300, 6.02214076e23})
    EXPECT_EQ(std::strtod(format_number(x, f).c_str(), nullptr), x) << x;
  f.integer_digits = true;  // scene messages: all integer digits below a million
  EXPECT_EQ(format_number(604800.0, f), "604800");
  EXPECT_EQ(format_number(1e6, f), "1e+06");
}

TEST(FormatNumber, SignedZeroAndNonFiniteTextAreChosenByTheCaller) {
  NumberFormat f;
  f.digits = 17;
  f.signed_zero = true;
  EXPECT_EQ(format_number(-0.0, f), "-0");
  EXPECT_EQ(format_number(0.1, f), "0.10000000000000001");  // MJCF: 17 digits
  f.non_finite = "—";
  EXPECT_EQ(format_number(kNan, f), "—");
  EXPECT_EQ(format_number(kInf, f), "—");
}

TEST(FormatNumber, DurationsPickTheirUnit) {
  EXPECT_EQ(fmt_duration_ns(512.0), "512 ns");
  EXPECT_EQ(fmt_duration_ns(1234.0), "1.23 µs");
  EXPECT_EQ(fmt_duration_ns(2.5e7), "25 ms");
  EXPECT_EQ(fmt_duration_ns(3.21e9), "3.21 s");
  EXPECT_EQ(fmt_duration_ns(kNan), "—");
}

}  // namespace
}  // namespace rbx
