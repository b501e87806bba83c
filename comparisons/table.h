// Plain-text tables and number formatting for the terminal.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "engine/math.h"

namespace rbx {

/// Number with `digits` significant digits ("%.*g"); "nan"/"inf" spelled out.
std::string fmt_num(double x, int digits = 6);
/// "(x, y, z)" with fmt_num.
std::string fmt_vec(const Vec3& v, int digits = 4);

/// A table with a header row, columns padded to width.
class Table {
 public:
  explicit Table(std::vector<std::string> header);
  /// Adds a row (as many cells as the header).
  void add(std::vector<std::string> row);
  /// Prints with two-space indentation and a rule under the header.
  void print(std::ostream& out) const;
  /// GitHub markdown table.
  std::string markdown() const;

 private:
  std::vector<std::vector<std::string>> rows_;
};

}  // namespace rbx
