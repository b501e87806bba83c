// The scene library: every scene loads, and every [expect] block holds (a test per block).
#include <gtest/gtest.h>

#include <filesystem>

#include "comparisons/commands.h"
#include "comparisons/harness.h"
#include "comparisons/scene_file.h"

namespace rbx {
namespace {

std::vector<std::string> library() {
  return collect_scene_files({std::string(RBX_SOURCE_DIR) + "/scenes"});
}

std::vector<std::string> with_expect() {
  std::vector<std::string> out;
  for (const std::string& f : library())
    if (load_scene(f).expect) out.push_back(f);
  return out;
}

std::string test_name(const testing::TestParamInfo<std::string>& info) {
  const std::filesystem::path p(info.param);
  std::string name = p.parent_path().filename().string() + "_" + p.stem().string();
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

TEST(SceneLibrary, EveryFamilyIsPresentWithAtLeastFortyScenes) {
  const auto files = library();
  EXPECT_GE(files.size(), 40u);
  for (const char* family : {"seed", "analytic", "contact", "stress", "many"}) {
    const bool found = std::any_of(files.begin(), files.end(), [&](const std::string& f) {
      return scene_family(f) == family;
    });
    EXPECT_TRUE(found) << family;
  }
}

class SceneLoads : public testing::TestWithParam<std::string> {};

TEST_P(SceneLoads, ParsesWithDescriptionAndChecks) {
  const Scene s = load_scene(GetParam());
  EXPECT_FALSE(s.description.empty()) << GetParam();
  EXPECT_FALSE(s.checks.empty()) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Library, SceneLoads, testing::ValuesIn(library()), test_name);

// [expect] binds the subjects: the custom engine for final states, the exact oracle for
// contacts. The tolerance is the scene's own, justified in its file.
class SceneExpect : public testing::TestWithParam<std::string> {};

TEST_P(SceneExpect, ClosedFormHolds) {
  const Scene s = load_scene(GetParam());
  HarnessOptions opt;
  opt.backends = "custom,exact";
  opt.sweep = false;
  const SceneEvaluation ev = evaluate_scene(s, opt);
  EXPECT_TRUE(ev.json["expect"]["checked"].get<bool>());
  for (const std::string& f : ev.expect_failures) ADD_FAILURE() << GetParam() << ": " << f;
}

INSTANTIATE_TEST_SUITE_P(Library, SceneExpect, testing::ValuesIn(with_expect()), test_name);

}  // namespace
}  // namespace rbx
