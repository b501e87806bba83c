// The figure scripts run without a shell (comparisons/output/figure_script.h): a path holding
// quotes, spaces or a command substitution reaches the script as it is.
#include "comparisons/output/figure_script.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace rbx {
namespace {

// A folder whose name a shell would split, unquote and run a command from.
fs::path awkward_dir() {
  const fs::path p = fs::temp_directory_path() /
                     ("rbx it's $(touch pwned_" + std::to_string(getpid()) + ") `x` dir");
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(FigureScript, APathAShellWouldSplitReachesTheScriptAsItIs) {
  const fs::path dir = awkward_dir();
  // The smallest explore.json the explore figure draws from: one backend, one sample.
  std::ofstream(dir / "explore.json") << R"({"count": 1, "seed": 1, "backends": {"custom":
    {"errors": {"normal_err_deg": {"n": 1, "quantiles_every_5": [1e-3,
     1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3,
     1e-3, 1e-3, 1e-3, 1e-3, 1e-3]}, "depth_err_rel": {"n": 0}, "point_err_rel": {"n": 0}}}}})";
  const fs::path log = dir / "figures.log";
  std::string why;
  EXPECT_EQ(run_figure_script("explore_plots.py", {dir.string()}, log.string(), &why), 0)
      << why << read(log);
  EXPECT_TRUE(fs::exists(dir / "explore_errors.png"));
  // No shell ran the substitution, here or in the folder's parent.
  const std::string pwned = "pwned_" + std::to_string(getpid());
  EXPECT_FALSE(fs::exists(fs::current_path() / pwned));
  EXPECT_FALSE(fs::exists(dir.parent_path() / pwned));
  fs::remove_all(dir);
}

TEST(FigureScript, AFailingScriptGivesItsStatusAndItsErrorInTheLog) {
  const fs::path dir = awkward_dir();
  const fs::path log = dir / "figures.log";
  // No explore.json: the script stops with Python's error, on stderr, into the log.
  EXPECT_GT(run_figure_script("explore_plots.py", {dir.string()}, log.string()), 0);
  EXPECT_NE(read(log).find("explore.json"), std::string::npos) << read(log);
  // A kind whose errors the figure does not draw (a landing's): one line saying so, no figure.
  std::ofstream(dir / "explore.json") << R"({"kind": "landing", "backends": {"ode":
    {"errors": {"position_err_m": {"n": 0}}}}})";
  EXPECT_GT(run_figure_script("explore_plots.py", {dir.string()}, log.string()), 0);
  EXPECT_NE(read(log).find("no contact-kind errors"), std::string::npos) << read(log);
  EXPECT_FALSE(fs::exists(dir / "explore_errors.png"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rbx
