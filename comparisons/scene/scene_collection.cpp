#include "comparisons/scene/scene_collection.h"

#include <algorithm>
#include <filesystem>

#include "comparisons/scene/repo_path.h"
#include "comparisons/scene/scene_file.h"

namespace fs = std::filesystem;

namespace rbx {

std::vector<std::string> collect_scene_files(const std::vector<std::string>& inputs) {
  std::vector<std::string> roots = inputs;
  if (roots.empty()) roots.push_back(default_repo_path("scenes"));
  std::vector<std::string> files;
  for (const std::string& root : roots) {
    std::error_code ec;
    if (fs::is_directory(root, ec)) {
      std::vector<std::string> found;
      for (const auto& e : fs::recursive_directory_iterator(root))
        if (e.is_regular_file() && e.path().extension() == ".toml")
          found.push_back(e.path().string());
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::exists(root, ec)) {
      files.push_back(root);
    } else {
      throw InputError(root + ": no such scene file or folder");
    }
  }
  if (files.empty()) throw InputError("no scene files (*.toml) found under the given inputs");
  return files;
}

std::string scene_family(const std::string& file) {
  const std::filesystem::path p(file);
  const std::string parent = p.parent_path().filename().string();
  return parent.empty() ? "scenes" : parent;
}

}  // namespace rbx
