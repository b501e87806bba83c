#include "comparisons/output/table.h"

#include <algorithm>

namespace rbx {

std::string csv_escape(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

Table::Table(std::vector<std::string> header) { rows_.push_back(std::move(header)); }

void Table::add(std::vector<std::string> row) {
  row.resize(rows_.front().size());
  rows_.push_back(std::move(row));
}

void Table::print(std::ostream& out) const {
  std::vector<size_t> width(rows_.front().size(), 0);
  for (const auto& r : rows_)
    for (size_t c = 0; c < r.size(); ++c) width[c] = std::max(width[c], r[c].size());
  for (size_t i = 0; i < rows_.size(); ++i) {
    std::string line = " ";
    for (size_t c = 0; c < rows_[i].size(); ++c)
      line += " " + rows_[i][c] + std::string(width[c] - rows_[i][c].size(), ' ');
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << "\n";
    if (i == 0) {
      std::string rule = " ";
      for (size_t c = 0; c < width.size(); ++c) rule += " " + std::string(width[c], '-');
      out << rule << "\n";
    }
  }
}

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Table::html(const std::vector<std::string>& row_classes) const {
  std::string s = "<table>\n<thead><tr>";
  for (const std::string& cell : rows_.front()) s += "<th>" + html_escape(cell) + "</th>";
  s += "</tr></thead>\n<tbody>\n";
  for (size_t i = 1; i < rows_.size(); ++i) {
    const std::string cls = i - 1 < row_classes.size() ? row_classes[i - 1] : "";
    s += cls.empty() ? "<tr>" : "<tr class=\"" + html_escape(cls) + "\">";
    for (const std::string& cell : rows_[i]) s += "<td>" + html_escape(cell) + "</td>";
    s += "</tr>\n";
  }
  return s + "</tbody>\n</table>\n";
}

std::string Table::markdown() const {
  std::string s;
  for (size_t i = 0; i < rows_.size(); ++i) {
    s += "|";
    for (const std::string& cell : rows_[i]) s += " " + cell + " |";
    s += "\n";
    if (i == 0) {
      s += "|";
      for (size_t c = 0; c < rows_[i].size(); ++c) s += "---|";
      s += "\n";
    }
  }
  return s;
}

}  // namespace rbx
