// The dependency order of the source folders, checked on the includes: engine/ < reference/ <
// comparisons/scene/ < comparisons/eval/ < comparisons/output/ < comparisons/cli/. A file may
// include its own layer and the layers below it, never one above (docs/style.md: "nothing points
// backwards"). The CMake libraries enforce the same order for symbols (comparisons/CMakeLists.txt).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// The layers, lowest first, as path prefixes relative to the source root.
const std::vector<std::string> kLayers = {
    "engine/",           "reference/",          "comparisons/scene/",
    "comparisons/eval/", "comparisons/output/", "comparisons/cli/"};

// Rank of a path in kLayers, or -1 when it is in none (system headers, tests).
int layer_of(const std::string& path) {
  for (std::size_t i = 0; i < kLayers.size(); ++i)
    if (path.rfind(kLayers[i], 0) == 0) return static_cast<int>(i);
  return -1;
}

// Every quoted include of `text` (the file at `path`) that names a higher layer than the file's,
// as "path: includes X".
std::vector<std::string> upward_includes(const std::string& path, const std::string& text) {
  std::vector<std::string> out;
  const int own = layer_of(path);
  static const std::regex include_re(R"re(^\s*#\s*include\s*"([^"]+)")re");
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::smatch m;
    if (!std::regex_search(line, m, include_re)) continue;
    const int target = layer_of(m[1].str());
    if (target > own) out.push_back(path + ": includes " + m[1].str());
  }
  return out;
}

// Source files (.h, .cpp) under `folder` of the source tree, relative to the root.
std::vector<std::string> sources_under(const std::string& folder) {
  std::vector<std::string> out;
  const fs::path root(RBX_SOURCE_DIR);
  for (const auto& e : fs::recursive_directory_iterator(root / folder)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".h" || ext == ".cpp"))
      out.push_back(fs::relative(e.path(), root).generic_string());
  }
  return out;
}

std::string read(const std::string& relative) {
  std::ifstream in(fs::path(RBX_SOURCE_DIR) / relative);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(Layers, AnUpwardIncludeIsFound) {
  // The checker itself: an eval file including the CLI header is a violation; the same file
  // including scene and engine headers is not.
  EXPECT_EQ(
      upward_includes("comparisons/eval/x.cpp", "#include \"comparisons/cli/commands.h\"\n"),
      std::vector<std::string>{"comparisons/eval/x.cpp: includes comparisons/cli/commands.h"});
  EXPECT_EQ(upward_includes("reference/x.cpp", "  # include \"comparisons/scene/scene_file.h\""),
            std::vector<std::string>{"reference/x.cpp: includes comparisons/scene/scene_file.h"});
  EXPECT_TRUE(
      upward_includes("comparisons/eval/x.cpp",
                      "#include \"comparisons/scene/mesh_io.h\"\n#include \"engine/body.h\"\n"
                      "#include <vector>\n")
          .empty());
}

TEST(Layers, NoSourceFileIncludesAHigherLayer) {
  std::size_t files = 0;
  for (const char* folder : {"engine", "reference", "comparisons"})
    for (const std::string& f : sources_under(folder)) {
      ++files;
      for (const std::string& v : upward_includes(f, read(f))) ADD_FAILURE() << v;
    }
  EXPECT_GT(files, 40u);  // the tree was found (about 70 files)
}

TEST(Layers, EveryComparisonsSourceIsInALayer) {
  // A file straight in comparisons/ would belong to no layer and escape the check above.
  for (const std::string& f : sources_under("comparisons"))
    EXPECT_GE(layer_of(f), 0) << f << " is outside comparisons/{scene,eval,output,cli}/";
}

TEST(Layers, TheEngineAndTheAdaptersKnowNoComparisonsVocabulary) {
  // A world is bodies, settings and a contact model (engine/world_definition.h); what the
  // harness checks, expects, repeats or which backends it runs belongs to comparisons/scene/.
  // Code only, comments aside: a comment may say what a caller does with a result.
  static const std::regex word_re(
      R"re(\b(Scene|CheckKind|Expect|ExpectBody|ExpectContact|EnsembleSpec|known_failure)\b)re");
  std::size_t files = 0;
  for (const char* folder : {"engine", "reference"})
    for (const std::string& f : sources_under(folder)) {
      ++files;
      std::istringstream lines(read(f));
      std::string line;
      for (int n = 1; std::getline(lines, line); ++n) {
        const std::string code = line.substr(0, line.find("//"));
        std::smatch m;
        if (std::regex_search(code, m, word_re))
          ADD_FAILURE() << f << ":" << n << " names " << m[1] << ": " << line;
      }
    }
  EXPECT_GT(files, 40u);  // the tree was found
}

// Lines of the .h and .cpp files under `folder`.
std::size_t lines_under(const std::string& folder) {
  std::size_t n = 0;
  for (const std::string& f : sources_under(folder)) {
    const std::string text = read(f);
    n += static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
  }
  return n;
}

TEST(Layers, CommandsParseAndCallTheLayersBelow) {
  // A command parses its arguments, calls eval/ and output/ and sets the exit code: it never
  // reaches into an adapter or runs the engine's world itself (docs/style.md).
  static const std::regex reach_re(R"re(^\s*#\s*include\s*"(reference/[^"]+|engine/world\.h)")re");
  for (const std::string& f : sources_under("comparisons/cli")) {
    std::istringstream lines(read(f));
    std::string line;
    while (std::getline(lines, line))
      if (std::regex_search(line, reach_re)) ADD_FAILURE() << f << ": " << line;
  }
  // What computes or writes lives below: the command layer stays the smaller one.
  EXPECT_LT(lines_under("comparisons/cli"), lines_under("comparisons/output"));
}

TEST(Layers, NoSourceFileIsOver900LinesNorAComparisonsFileOver600) {
  // A file past 900 lines holds more than one idea (docs/style.md): split it by what it does. The
  // bench's files (comparisons/) hold less arithmetic per line than the engine's and the
  // adapters', so they split sooner: each of the last five past 600 lines was two ideas (an
  // explore kind beside another, the "Why" list beside the report writer).
  for (const char* folder : {"engine", "reference", "comparisons"})
    for (const std::string& f : sources_under(folder)) {
      const std::string text = read(f);
      const long limit = std::string(folder) == "comparisons" ? 600 : 900;
      EXPECT_LE(std::count(text.begin(), text.end(), '\n'), limit) << f;
    }
}
