#include "comparisons/output/backend_style.h"

#include <nlohmann/json.hpp>

#include "asset_backend_style_json.h"
#include "comparisons/output/table.h"  // html_escape

namespace rbx {

std::string backend_colour(const std::string& name) {
  static const nlohmann::json table = nlohmann::json::parse(kBackendStyle);
  return table.contains(name) ? table[name][0].get<std::string>() : "#777777";
}

std::string backend_legend_html(const std::vector<std::string>& names) {
  std::string h = "<p class=\"legend\">Colours, the same in every figure and replay:";
  for (const std::string& n : names)
    h += " <span style=\"white-space:nowrap\"><span style=\"display:inline-block;width:.9em;"
         "height:.9em;vertical-align:-.1em;background:" +
         backend_colour(n) + "\"></span> " + html_escape(n) + "</span>";
  return h + "</p>\n";
}

}  // namespace rbx
