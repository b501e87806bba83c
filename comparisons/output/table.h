// Plain-text and markdown tables for the terminal and the reports.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "engine/format.h"  // fmt_num and fmt_vec, for the cells

namespace rbx {

/// Text safe inside HTML element content and attribute values (& < > " ').
std::string html_escape(const std::string& s);

/// A CSV cell: `s` as it is, or quoted (quotes doubled) when it holds a comma, quote or newline.
std::string csv_escape(const std::string& s);

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
  /// HTML table, every cell escaped; row i (below the header) gets class `row_classes[i]` when
  /// given and non-empty.
  std::string html(const std::vector<std::string>& row_classes = {}) const;
  /// Number of rows below the header.
  size_t size() const { return rows_.empty() ? 0 : rows_.size() - 1; }

 private:
  std::vector<std::vector<std::string>> rows_;
};

}  // namespace rbx
