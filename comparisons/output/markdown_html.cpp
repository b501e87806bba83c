#include "comparisons/output/markdown_html.h"

#include <md4c-html.h>

#include <cctype>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "comparisons/output/table.h"  // html_escape

namespace rbx {

namespace {

bool is_word(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; }

// The slug of a heading's plain text (see heading_anchor).
std::string slug(const std::string& text) {
  std::string id;
  for (char c : text) {
    if (is_word(c) || c == '-' || c == '_')
      id += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    else if (!id.empty() && id.back() != '-')
      id += '-';
  }
  while (!id.empty() && id.back() == '-') id.pop_back();
  return id;
}

// Markdown backslash escapes removed (md_escape's inverse): "\_" is "_".
std::string unescape(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 1 < s.size()) ++i;
    out += s[i];
  }
  return out;
}

// The text of rendered HTML: tags dropped, the entities md4c writes decoded.
std::string html_text(const std::string& html) {
  static const std::pair<const char*, char> kEntities[] = {
      {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}};
  std::string out;
  for (size_t i = 0; i < html.size(); ++i) {
    if (html[i] == '<') {
      const size_t close = html.find('>', i);
      if (close == std::string::npos) break;
      i = close;
      continue;
    }
    bool decoded = false;
    for (const auto& [name, c] : kEntities)
      if (html.compare(i, std::strlen(name), name) == 0) {
        out += c;
        i += std::strlen(name) - 1;
        decoded = true;
        break;
      }
    if (!decoded) out += html[i];
  }
  return out;
}

// Every <hN> of md4c's output given the id its text names (md4c writes headings bare).
std::string with_heading_anchors(const std::string& html) {
  std::string out;
  size_t from = 0;
  for (;;) {
    size_t open = html.find("<h", from);
    while (open != std::string::npos && !(open + 3 < html.size() && html[open + 2] >= '1' &&
                                          html[open + 2] <= '6' && html[open + 3] == '>'))
      open = html.find("<h", open + 2);
    if (open == std::string::npos) break;
    const std::string close = "</h" + std::string(1, html[open + 2]) + ">";
    const size_t end = html.find(close, open);
    if (end == std::string::npos) break;
    out.append(html, from, open + 3 - from);
    out += " id=\"" + html_escape(slug(html_text(html.substr(open + 4, end - open - 4)))) + "\"";
    from = open + 3;
  }
  return out + html.substr(from);
}

void append(const MD_CHAR* text, MD_SIZE size, void* out) {
  static_cast<std::string*>(out)->append(text, size);
}

}  // namespace

std::string heading_anchor(const std::string& text) { return slug(unescape(text)); }

std::string markdown_to_html(const std::string& md) {
  std::string html;
  // Tables as GitHub writes them; raw HTML blocks and spans are text, escaped like any other.
  if (md_html(md.data(), static_cast<MD_SIZE>(md.size()), append, &html,
              MD_FLAG_TABLES | MD_FLAG_NOHTML, 0) != 0)
    throw std::runtime_error("md4c could not render the report's Markdown");
  return with_heading_anchors(html);
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
