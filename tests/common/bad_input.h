// The bad-input catalogue (tests/bad_input/): each NAME.toml with its one expected line in
// NAME.expected, shared by the parser's tests and the command-line tests.
#pragma once

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace rbx::test {

/// The catalogue's entries: stems of tests/bad_input/*.toml, sorted.
inline std::vector<std::string> bad_input_catalogue() {
  std::vector<std::string> names;
  const std::filesystem::path folder = std::filesystem::path(RBX_SOURCE_DIR) / "tests/bad_input";
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    if (entry.path().extension() == ".toml") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace rbx::test
