#include "comparisons/scene/repo_path.h"

#include <filesystem>
#include <system_error>

namespace rbx {

std::string default_repo_path(const std::string& relative) {
  namespace fs = std::filesystem;
  const fs::path root(RBX_DEFAULT_SOURCE_DIR);
  std::error_code ec;
  // At the root (or when the source tree is gone: a binary moved elsewhere) the plain relative
  // path, as before; elsewhere the repository's own folder.
  if (!fs::is_directory(root, ec) || fs::equivalent(fs::current_path(ec), root, ec))
    return relative;
  return (root / relative).string();
}

}  // namespace rbx
