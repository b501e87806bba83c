// The report's pages in HTML from the Markdown the report writes: headings (with anchors),
// paragraphs, lists, tables, images, links, bold, italic and code. Only that subset, the one
// rbx itself writes; every character of text is HTML-escaped, so a scene's text (already
// Markdown-escaped by md_escape) can never become markup.
#pragma once

#include <string>

namespace rbx {

/// The anchor (HTML id) of a heading with this text, once Markdown escapes are removed:
/// lower case; letters, digits, '-' and '_' kept, every other run of characters one '-'.
std::string heading_anchor(const std::string& text);

/// The HTML body of a Markdown text (the subset above).
std::string markdown_to_html(const std::string& md);

/// A whole offline page: `title` (escaped), the report's style sheet, `body` as given.
std::string html_page(const std::string& title, const std::string& body);

}  // namespace rbx
