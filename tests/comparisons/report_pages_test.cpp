// The report a reader opens first: report.md and index.html (output/report_pages.h), their
// Markdown-to-HTML rendering (output/markdown_html.h) and the ranked scorecard
// (output/scorecard.h): every link and image resolves, the unit of a row follows what it
// measures, scene text never becomes markup.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "comparisons/output/backend_style.h"
#include "comparisons/output/markdown_html.h"
#include "comparisons/output/scorecard.h"  // md_escape, md_code, md_url
#include "comparisons/output/table.h"      // html_escape
#include "tests/common/fixtures.h"

namespace fs = std::filesystem;

namespace rbx {
namespace {

using test::temp_dir;

std::string read(const fs::path& p) {
  std::stringstream s;
  s << std::ifstream(p).rdbuf();
  return s.str();
}

// `rbx report ARGS` from the source folder; the exit code.
int report(const std::string& args) {
  const std::string cmd = "cd '" RBX_SOURCE_DIR "' && '" RBX_BINARY_DIR
                          "/comparisons/rbx' report " +
                          args + " > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A folder mixing a contact scene and dynamics scenes (one family, two measures), one of them
// with a description that is markup.
const char* const kOddFamily = "odd (fam) #1";
const char* const kOddFile = "a b(1)`c\"d.toml";

// A link's target with its %XX escapes decoded: the file name the browser asks for.
std::string url_decoded(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size()) {
      out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

fs::path mixed_folder(const fs::path& dir) {
  const fs::path mixed = dir / "mixed";
  fs::create_directories(mixed);
  fs::copy_file(RBX_SOURCE_DIR "/scenes/contact/axis_x.toml", mixed / "axis_x.toml");
  // A family of contact scenes only: its figure is the "-contact" one.
  fs::create_directories(dir / "touch");
  fs::copy_file(RBX_SOURCE_DIR "/scenes/contact/axis_y.toml", dir / "touch/axis_y.toml");
  fs::copy_file(RBX_SOURCE_DIR "/scenes/analytic/headon_e05.toml", mixed / "headon_e05.toml");
  std::string text = read(RBX_SOURCE_DIR "/scenes/analytic/headon_e1.toml");
  text = std::regex_replace(text, std::regex("\ndescription = \"[^\"]*\""),
                            "\ndescription = \"<b>bold</b> *x* [l](javascript:alert(1))\"");
  std::ofstream(mixed / "markup.toml") << text;
  // A folder and a file whose names hold what would end a link, a code span, an attribute or a
  // heading's anchor: their figures, replays and anchors must still be found.
  fs::create_directories(dir / kOddFamily);
  fs::copy_file(RBX_SOURCE_DIR "/scenes/analytic/headon_e05.toml", dir / kOddFamily / kOddFile);
  return mixed;
}

// Every local target of href="..." and src="..." in an HTML page exists, and every "#id" it
// names is an id of the target page.
void expect_html_links_resolve(const fs::path& page) {
  const std::string html = read(page);
  const std::regex attr("(href|src)=\"([^\"]*)\"");
  int checked = 0;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), attr); it != std::sregex_iterator();
       ++it) {
    const std::string target = (*it)[2];
    ASSERT_EQ(target.find("://"), std::string::npos) << page << ": not offline: " << target;
    ASSERT_NE(target.rfind("javascript:", 0), 0u) << page << ": " << target;
    const size_t hash = target.find('#');
    const std::string file = target.substr(0, hash);
    const fs::path path = file.empty() ? page : page.parent_path() / url_decoded(file);
    EXPECT_TRUE(fs::exists(path)) << page << " links " << target;
    if (hash != std::string::npos && fs::exists(path)) {
      EXPECT_NE(read(path).find("id=\"" + target.substr(hash + 1) + "\""), std::string::npos)
          << page << " links " << target;
    }
    ++checked;
  }
  EXPECT_GT(checked, 0) << page;
}

// Every local target of ](...) in a Markdown file exists.
void expect_markdown_links_resolve(const fs::path& md_file) {
  const std::string md = read(md_file);
  // An escaped "\]" is text (a scene's), not the end of a link.
  const std::regex link("(^|[^\\\\])\\]\\(([^)#]+)[^)]*\\)");
  int checked = 0;
  for (auto it = std::sregex_iterator(md.begin(), md.end(), link); it != std::sregex_iterator();
       ++it) {
    EXPECT_TRUE(fs::exists(md_file.parent_path() / url_decoded((*it)[2].str())))
        << md_file << ": " << (*it)[2];
    ++checked;
  }
  EXPECT_GT(checked, 0) << md_file;
}

// One report (a report costs tens of seconds under the sanitizers) of a folder mixing contact
// and dynamics scenes, a contact-only folder and a mass scene, judged three ways.
TEST(ReportPages, LinksResolveUnitsFollowTheMetricAndSceneTextStaysText) {
  const fs::path dir = temp_dir("report_pages");
  const fs::path mixed = mixed_folder(dir), out = dir / "out";
  ASSERT_EQ(report("'" + mixed.string() + "' '" + (dir / "touch").string() + "' '" +
                   (dir / kOddFamily).string() + "' scenes/mass/box_1x2x3.toml --out '" +
                   out.string() + "'"),
            0);
  // Every link and image resolves.
  for (const char* page : {"index.html", "details.html"}) expect_html_links_resolve(out / page);
  for (const char* md : {"report.md", "details.md"}) expect_markdown_links_resolve(out / md);
  // The figures are inline in the page, and each scene links its numbers and its replay.
  const std::string index = read(out / "index.html");
  EXPECT_NE(index.find("<img src=\"figures/error_vs_runtime_"), std::string::npos);
  EXPECT_NE(index.find("href=\"details.html#mixed-headon_e05"), std::string::npos) << index;
  EXPECT_NE(index.find("href=\"views/mixed_headon_e05.html\""), std::string::npos);
  // The odd names: the replay's file is named as the scene's, its link percent-encoded, the
  // file name shown whole in its code span.
  EXPECT_TRUE(fs::exists(out / "views" / (std::string(kOddFamily) + "_a b(1)`c\"d.html")));
  EXPECT_NE(index.find("href=\"views/odd%20%28fam%29%20%231_a%20b%281%29%60c%22d.html\""),
            std::string::npos)
      << index;
  EXPECT_NE(read(out / "details.html").find("a b(1)`c&quot;d.toml</code>"), std::string::npos);
  // The colour key of the figures names each backend in its colour (its registry entry),
  // and a replay page's data carries the same colour for its panel.
  EXPECT_NE(index.find("background:" + backend_colour("custom") + "\"></span> custom<"),
            std::string::npos);
  EXPECT_NE(read(out / "views/mixed_headon_e05.html")
                .find("\"colour\":\"" + backend_colour("custom") + "\""),
            std::string::npos);

  // The unit of a row follows what it measures. The summary's scorecard: one column per family
  // and measure, the contact column in degrees, the dynamics one not.
  const std::string summary = read(out / "report.md");
  const size_t header = summary.find("| backend | mixed (contacts) | mixed (dynamics) |");
  ASSERT_NE(header, std::string::npos) << summary;
  const size_t custom_row = summary.find("\n| **custom** | #", header);
  ASSERT_NE(custom_row, std::string::npos) << summary;
  const std::string cells =
      summary.substr(custom_row + 16, summary.find('\n', custom_row + 1) - custom_row - 16);
  const size_t split = cells.find(" | ");
  ASSERT_NE(split, std::string::npos) << cells;
  const std::string dynamics_cell =
      cells.substr(split + 3, cells.find(" | ", split + 3) - split - 3);
  EXPECT_NE(cells.substr(0, split).find("°"), std::string::npos) << cells;
  EXPECT_NE(dynamics_cell.find("#"), std::string::npos) << cells;
  EXPECT_EQ(dynamics_cell.find("°"), std::string::npos) << cells;
  // details.md: one family, two measures: one ranked table each, in its own unit.
  const std::string md = read(out / "details.md");
  const size_t contacts = md.find("### mixed — contacts:");
  const size_t dynamics = md.find("### mixed — dynamics:");
  ASSERT_NE(contacts, std::string::npos) << md;
  ASSERT_NE(dynamics, std::string::npos) << md;
  auto table_after = [&](size_t at) {
    const size_t start = md.find("\n|", at);
    return md.substr(start, md.find("\n\n", start) - start);
  };
  const std::string c = table_after(contacts), d = table_after(dynamics);
  EXPECT_NE(c.find("°"), std::string::npos) << c;
  EXPECT_NE(c.find("µs/query"), std::string::npos) << c;
  EXPECT_EQ(c.find("µs/step"), std::string::npos) << c;
  // A velocity error is not an angle, and a step is not a query.
  EXPECT_EQ(d.find("°"), std::string::npos) << d;
  EXPECT_EQ(d.find("µs/query"), std::string::npos) << d;
  EXPECT_NE(d.find("µs/step"), std::string::npos) << d;

  // Scene text never becomes markup.
  for (const char* page : {"index.html", "details.html"}) {
    const std::string html = read(out / page);
    EXPECT_EQ(html.find("<b>bold</b>"), std::string::npos) << page;
    EXPECT_EQ(html.find("href=\"javascript:"), std::string::npos) << page;
    EXPECT_NE(html.find("&lt;b&gt;bold&lt;/b&gt;"), std::string::npos) << page;
  }
  fs::remove_all(dir);
}

TEST(MarkdownHtml, ACodeSpanShowsAnyTextAndALinkTargetFindsAnyFileName) {
  // Each text comes back exactly (HTML-escaped), one code span, whatever backticks and spaces it
  // holds; a line break is a space.
  const std::vector<std::pair<std::string, std::string>> spans = {
      {"plain", "plain"},   {"a`b", "a`b"},   {"``x``", "``x``"},     {"`lead", "`lead"},
      {"trail`", "trail`"}, {" sp ", " sp "}, {"a*b*_c_", "a*b*_c_"}, {"<i>&", "&lt;i&gt;&amp;"},
      {"a\nb", "a b"}};
  for (const auto& [text, shown] : spans)
    EXPECT_EQ(markdown_to_html("x " + md_code(text) + " y"),
              "<p>x <code>" + shown + "</code> y</p>\n")
        << text;
  // A target with spaces, parentheses, a quote and a '#' stays one link to that name.
  EXPECT_EQ(md_url("views/odd (fam) #1_a\"b.html"), "views/odd%20%28fam%29%20%231_a%22b.html");
  EXPECT_EQ(markdown_to_html("[l](" + md_url("f/a (b).png") + ")"),
            "<p><a href=\"f/a%20%28b%29.png\">l</a></p>\n");
}

TEST(MarkdownHtml, RendersTheReportsMarkdownWithHeadingAnchorsAndTables) {
  const std::string html = markdown_to_html(
      "# A \\<title\\>\n\nText with **bold**, _it_, `a<b`, a [link](x.html#y) and "
      "![fig](f.png).\n\n| a | b\\|c |\n|---|---|\n| 1 | <i> |\n\n- one\n  - nested\n- two\n");
  EXPECT_NE(html.find("<h1 id=\"a-title\">A &lt;title&gt;</h1>"), std::string::npos) << html;
  EXPECT_NE(html.find("<strong>bold</strong>"), std::string::npos) << html;
  EXPECT_NE(html.find("<em>it</em>"), std::string::npos) << html;
  EXPECT_NE(html.find("<code>a&lt;b</code>"), std::string::npos) << html;
  EXPECT_NE(html.find("<a href=\"x.html#y\">link</a>"), std::string::npos) << html;
  EXPECT_NE(html.find("<img src=\"f.png\" alt=\"fig\">"), std::string::npos) << html;
  EXPECT_NE(html.find("<th>b|c</th>"), std::string::npos) << html;
  // Raw HTML in the Markdown is text, not markup.
  EXPECT_NE(html.find("<td>&lt;i&gt;</td>"), std::string::npos) << html;
  EXPECT_EQ(html.find("<i>"), std::string::npos) << html;
  // The nested item is a list inside the first item (valid HTML: a <ul> sits in an <li>).
  const size_t one = html.find("<li>one"), nested = html.find("<ul>", one),
               close = html.find("</li>", one);
  ASSERT_NE(one, std::string::npos) << html;
  EXPECT_LT(nested, close) << html;
  EXPECT_NE(html.find("<li>nested</li>"), std::string::npos) << html;
  // An escaped underscore in a name is text, not emphasis.
  EXPECT_EQ(markdown_to_html("a\\_b\\_c"), "<p>a_b_c</p>\n");
  EXPECT_EQ(heading_anchor("analytic/corner\\_drop\\_e05"), "analytic-corner_drop_e05");
  // Every heading level gets its anchor, from the heading's text (markup dropped).
  EXPECT_EQ(markdown_to_html("### Error against `run` time\n"),
            "<h3 id=\"error-against-run-time\">Error against <code>run</code> time</h3>\n");
}

TEST(MarkdownHtml, AnyTextThroughMdEscapeStaysOneParagraphOfText) {
  // Scene names and descriptions are a user's text: whatever Markdown or HTML they hold, once
  // md_escape'd they render as the same characters, escaped, in one paragraph.
  const std::string hostile[] = {
      "<b>bold</b> & <script>alert(1)</script>",
      "[click](javascript:alert(1)) ![x](y.png) <http://example.com>",
      "**strong** _em_ `code` ~~gone~~ a|b # not a heading",
      "- not a list",
      "+ not a list",
      "12. not a list",
      "3) not a list",
      "&lt;b&gt; &amp; &#60;",
      "> not a quote",
      "line one\nline two",
      "    four spaces: not code",
      "\tindented by a tab",
      "  - indented list",
  };
  for (const std::string& text : hostile) {
    const std::string html = markdown_to_html(md_escape(text) + "\n");
    // What is shown: the text without its leading indentation, line breaks as spaces.
    std::string flat = text.substr(text.find_first_not_of(" \t"));
    for (char& c : flat)
      if (c == '\n') c = ' ';
    EXPECT_EQ(html, "<p>" + html_escape(flat) + "</p>\n") << text;
    // The same text as a table cell.
    const std::string cell = markdown_to_html("| h |\n|---|\n| " + md_escape(text) + " |\n");
    EXPECT_NE(cell.find("<td>" + html_escape(flat) + "</td>"), std::string::npos) << cell;
  }
}

}  // namespace
}  // namespace rbx
