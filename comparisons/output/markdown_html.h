// The report's pages in HTML from the Markdown the report writes, rendered by md4c (CommonMark
// with GitHub's tables). Raw HTML in the Markdown is not passed through: it is text like any
// other, so a scene's text (already Markdown-escaped by md_escape) can never become markup.
// Each heading gets an anchor (an HTML id) computed from its text, as GitHub names them.
#pragma once

#include <string>

namespace rbx {

/// The anchor (HTML id) of a heading with this text, once Markdown escapes are removed:
/// lower case; letters, digits, '-' and '_' kept, every other run of characters one '-'.
std::string heading_anchor(const std::string& text);

/// The HTML body of a Markdown text; throws std::runtime_error if md4c cannot parse it (it
/// fails only when it cannot allocate).
std::string markdown_to_html(const std::string& md);

/// A whole offline page: `title` (escaped), the report's style sheet, `body` as given.
std::string html_page(const std::string& title, const std::string& body);

}  // namespace rbx
