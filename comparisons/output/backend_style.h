// One colour per backend in every figure and page: each registry entry's style
// (reference/backend.h), read here for the pages and handed to the figure scripts
// (backend_style.py) by run_figure_script.
#pragma once

#include <string>
#include <vector>

namespace rbx {

/// The backend's colour ("#RRGGBB"); a name the table does not list gets grey.
std::string backend_colour(const std::string& name);

/// Every registered backend's style as the figure scripts read it (RBX_BACKEND_STYLE):
/// {"name": ["#RRGGBB", "marker"], ...} in registry order.
std::string backend_style_json();

/// An HTML line naming each backend in its colour (a square swatch before the name), the key
/// to every figure of a report.
std::string backend_legend_html(const std::vector<std::string>& names);

}  // namespace rbx
