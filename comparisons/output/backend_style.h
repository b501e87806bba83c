// One colour per backend in every figure and page: the table is output/assets/backend_style.json,
// read by the figure scripts (backend_style.py) and embedded here for the pages.
#pragma once

#include <string>
#include <vector>

namespace rbx {

/// The backend's colour ("#RRGGBB"); a name the table does not list gets grey.
std::string backend_colour(const std::string& name);

/// An HTML line naming each backend in its colour (a square swatch before the name), the key
/// to every figure of a report.
std::string backend_legend_html(const std::vector<std::string>& names);

}  // namespace rbx
