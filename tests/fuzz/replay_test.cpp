// Replays every committed fuzz input through its target's entry function, built with the normal
// compiler so that `./rbx test` (and `./rbx test --sanitize`) keep every bug the fuzzers found
// fixed: the regressions (inputs that once crashed or broke an invariant,
// tests/fuzz/regressions/<target>/) and the starting corpus (tests/fuzz/corpus/<target>/).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>
#include <typeinfo>
#include <vector>

#include "tests/fuzz/targets.h"

namespace rbx::fuzz {

// GoogleTest prints a parameter in test listings (and so in ctest's names): the target's name,
// not the bytes of its pointers.
void PrintTo(const Target& target, std::ostream* os) { *os << target.name; }

namespace {

namespace fs = std::filesystem;

// The files of a folder, sorted (an absent folder has none).
std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file() && entry.path().filename().string()[0] != '.')
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Feeds one file to the target; a broken invariant or a disallowed exception is a failure
// naming the file (a crash names it through the line printed first).
void replay(const Target& target, const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
  std::fprintf(stderr, "replaying %s\n", file.string().c_str());
  try {
    target.entry(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  } catch (const InvariantViolation& e) {
    ADD_FAILURE() << file << ": invariant violated: " << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << file << ": unexpected exception " << typeid(e).name() << ": " << e.what();
  }
}

class Replay : public ::testing::TestWithParam<Target> {};

TEST_P(Replay, Regressions) {
  const fs::path dir = fs::path(RBX_SOURCE_DIR) / "tests/fuzz/regressions" / GetParam().name;
  const std::vector<fs::path> files = files_in(dir);
  if (files.empty()) GTEST_SKIP() << "no regression inputs for " << GetParam().name;
  for (const fs::path& f : files) replay(GetParam(), f);
}

TEST_P(Replay, StartingCorpus) {
  const fs::path dir = fs::path(RBX_SOURCE_DIR) / "tests/fuzz/corpus" / GetParam().name;
  const std::vector<fs::path> files = files_in(dir);
  // Every target has a starting corpus of at least a handful of inputs (tests/fuzz/README.md).
  ASSERT_GE(files.size(), 5u) << dir;
  for (const fs::path& f : files) replay(GetParam(), f);
}

INSTANTIATE_TEST_SUITE_P(Fuzz, Replay, ::testing::ValuesIn(targets()),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace rbx::fuzz
