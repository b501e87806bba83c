#include "comparisons/output/markdown_html.h"

#include <cctype>
#include <sstream>
#include <vector>

#include "comparisons/output/table.h"  // html_escape

namespace rbx {

namespace {

bool is_word(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; }

// Markdown backslash escapes removed (md_escape's inverse): "\_" is "_".
std::string unescape(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 1 < s.size()) ++i;
    out += s[i];
  }
  return out;
}

// Index of the unescaped `close` at or after `from` (npos when none).
size_t find_closing(const std::string& s, size_t from, const std::string& close) {
  for (size_t i = from; i + close.size() <= s.size(); ++i) {
    if (s[i] == '\\') {
      ++i;
      continue;
    }
    if (s.compare(i, close.size(), close) == 0) return i;
  }
  return std::string::npos;
}

// The [text](href) starting at s[i] == '[': text, href and the index after ')'; false if none.
bool read_link(const std::string& s, size_t i, std::string& text, std::string& href,
               size_t& after) {
  const size_t close = find_closing(s, i + 1, "](");
  if (close == std::string::npos) return false;
  const size_t end = s.find(')', close + 2);
  if (end == std::string::npos) return false;
  text = s.substr(i + 1, close - i - 1);
  href = s.substr(close + 2, end - close - 2);
  after = end + 1;
  return true;
}

std::string inline_html(const std::string& s);

// One inline element at s[i], appended to `out`; returns the index after it, or i when s[i]
// starts none.
size_t inline_element(const std::string& s, size_t i, std::string& out) {
  std::string text, href;
  size_t after = 0;
  if (s.compare(i, 2, "![") == 0 && read_link(s, i + 1, text, href, after)) {
    out += "<img src=\"" + html_escape(href) + "\" alt=\"" + html_escape(unescape(text)) + "\">";
    return after;
  }
  if (s[i] == '[' && read_link(s, i, text, href, after)) {
    out += "<a href=\"" + html_escape(href) + "\">" + inline_html(text) + "</a>";
    return after;
  }
  if (s[i] == '`') {
    const size_t end = s.find('`', i + 1);  // code spans hold no escapes
    if (end != std::string::npos) {
      out += "<code>" + html_escape(s.substr(i + 1, end - i - 1)) + "</code>";
      return end + 1;
    }
  }
  if (s.compare(i, 2, "**") == 0) {
    const size_t end = find_closing(s, i + 2, "**");
    if (end != std::string::npos) {
      out += "<strong>" + inline_html(s.substr(i + 2, end - i - 2)) + "</strong>";
      return end + 2;
    }
  }
  // _emphasis_ or *emphasis*: opens after a non-word character, closes before one.
  const char mark = s[i];
  if ((mark == '_' || mark == '*') && (i == 0 || !is_word(s[i - 1])) && i + 1 < s.size() &&
      s[i + 1] != ' ') {
    const std::string close(1, mark);
    for (size_t end = find_closing(s, i + 1, close); end != std::string::npos;
         end = find_closing(s, end + 1, close))
      if (end + 1 == s.size() || !is_word(s[end + 1])) {
        out += "<em>" + inline_html(s.substr(i + 1, end - i - 1)) + "</em>";
        return end + 1;
      }
  }
  return i;
}

std::string inline_html(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size();) {
    if (s[i] == '\\' && i + 1 < s.size()) {
      out += html_escape(std::string(1, s[i + 1]));
      i += 2;
      continue;
    }
    const size_t next = inline_element(s, i, out);
    if (next != i) {
      i = next;
      continue;
    }
    out += html_escape(std::string(1, s[i]));
    ++i;
  }
  return out;
}

// The cells of a table row "| a | b |" (a "\|" inside a cell is text).
std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  for (size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '\\' && i + 1 < line.size()) {
      cell += line.substr(i, 2);
      ++i;
    } else if (line[i] == '|') {
      const size_t a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
      cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
      cell.clear();
    } else {
      cell += line[i];
    }
  }
  return cells;
}

bool starts_with(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }

// A Markdown table's lines (header, rule, rows) as an HTML table.
std::string table_html(const std::vector<std::string>& lines) {
  std::string h = "<table>\n<thead><tr>";
  for (const std::string& c : cells_of(lines[0])) h += "<th>" + inline_html(c) + "</th>";
  h += "</tr></thead>\n<tbody>\n";
  for (size_t k = 2; k < lines.size(); ++k) {
    h += "<tr>";
    for (const std::string& c : cells_of(lines[k])) h += "<td>" + inline_html(c) + "</td>";
    h += "</tr>\n";
  }
  return h + "</tbody>\n</table>\n";
}

// List lines ("- item", nested "  - item") as nested HTML lists.
std::string list_html(const std::vector<std::string>& lines) {
  std::string h;
  int depth = 0;
  for (const std::string& line : lines) {
    const int level = static_cast<int>(line.find('-') / 2) + 1;
    while (depth < level) h += "<ul>\n", ++depth;
    while (depth > level) h += "</ul>\n", --depth;
    h += "<li>" + inline_html(line.substr(line.find('-') + 2)) + "</li>\n";
  }
  while (depth-- > 0) h += "</ul>\n";
  return h;
}

bool is_list_line(const std::string& l) { return starts_with(l, "- ") || starts_with(l, "  - "); }

}  // namespace

std::string heading_anchor(const std::string& text) {
  std::string id;
  for (char c : unescape(text)) {
    if (is_word(c) || c == '-' || c == '_')
      id += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    else if (!id.empty() && id.back() != '-')
      id += '-';
  }
  while (!id.empty() && id.back() == '-') id.pop_back();
  return id;
}

std::string markdown_to_html(const std::string& md) {
  std::vector<std::string> lines;
  std::istringstream in(md);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  std::string html;
  for (size_t i = 0; i < lines.size();) {
    const std::string& l = lines[i];
    if (l.empty()) {
      ++i;
    } else if (l[0] == '#') {
      const size_t level = l.find_first_not_of('#');
      const std::string text = l.substr(std::min(l.size(), level + 1));
      const std::string tag = "h" + std::to_string(std::min<size_t>(level, 6));
      html += "<" + tag + " id=\"" + html_escape(heading_anchor(text)) + "\">" + inline_html(text) +
              "</" + tag + ">\n";
      ++i;
    } else if (l[0] == '|') {
      std::vector<std::string> rows;
      while (i < lines.size() && !lines[i].empty() && lines[i][0] == '|')
        rows.push_back(lines[i++]);
      html += rows.size() >= 2 ? table_html(rows) : "<p>" + inline_html(rows[0]) + "</p>\n";
    } else if (is_list_line(l)) {
      std::vector<std::string> items;
      while (i < lines.size() && is_list_line(lines[i])) items.push_back(lines[i++]);
      html += list_html(items);
    } else {
      // A paragraph: the lines up to a blank line or another block.
      std::string text;
      while (i < lines.size() && !lines[i].empty() && lines[i][0] != '#' && lines[i][0] != '|' &&
             !is_list_line(lines[i]))
        text += (text.empty() ? "" : " ") + lines[i++];
      html += "<p>" + inline_html(text) + "</p>\n";
    }
  }
  return html;
}

std::string html_page(const std::string& title, const std::string& body) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<meta "
         "name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
         html_escape(title) +
         "</title>\n<style>\n"
         "body{font:15px/1.45 system-ui,sans-serif;margin:1.5em auto;max-width:76em;padding:0 "
         "1em;color:#222}\n"
         "table{border-collapse:collapse;margin:.6em 0 1.2em;font-size:13px}\n"
         "th,td{border:1px solid #ccc;padding:.2em .5em;text-align:left;vertical-align:top}\n"
         "th{background:#f0f0f0}tbody tr:nth-child(even){background:#fafafa}\n"
         "img{max-width:100%;height:auto;display:block;margin:.5em 0}\n"
         "code{background:#f3f3f3;padding:0 .2em}h2{border-bottom:1px solid "
         "#ddd;margin-top:1.6em}\n"
         "nav a{margin-right:1em}\n"
         "</style></head><body>\n" +
         body + "</body></html>\n";
}

}  // namespace rbx
