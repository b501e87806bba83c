// A scene library on disk: which files make it up and how they group into families.
#pragma once

#include <string>
#include <vector>

namespace rbx {

/// Scene files under the inputs: folders searched recursively for *.toml (sorted), files taken
/// as given; no inputs means scenes/. Throws InputError for a missing input or no scene at all.
std::vector<std::string> collect_scene_files(const std::vector<std::string>& inputs);

/// The family of a scene file: its folder name under scenes/ ("seed", "analytic", ...).
std::string scene_family(const std::string& file);

}  // namespace rbx
