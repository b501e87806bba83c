#include "comparisons/output/backend_style.h"

#include "comparisons/eval/json_io.h"
#include "comparisons/output/table.h"  // html_escape
#include "reference/backend.h"

namespace rbx {

std::string backend_colour(const std::string& name) {
  const Backend* b = find_backend(name);
  return b && !b->style.colour.empty() ? b->style.colour : "#777777";
}

std::string backend_legend_html(const std::vector<std::string>& names) {
  std::string h = "<p class=\"legend\">Colours, the same in every figure and replay:";
  for (const std::string& n : names)
    h += " <span style=\"white-space:nowrap\"><span style=\"display:inline-block;width:.9em;"
         "height:.9em;vertical-align:-.1em;background:" +
         backend_colour(n) + "\"></span> " + html_escape(n) + "</span>";
  return h + "</p>\n";
}

std::string backend_style_json() {
  Json styles = Json::object();
  for (const Backend& b : backends())
    if (!b.style.colour.empty()) styles[b.name] = Json::array({b.style.colour, b.style.marker});
  return styles.dump();
}

}  // namespace rbx
