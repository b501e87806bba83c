// `rbx explore`: random samples against their truth over every core or MPI rank (comparisons/
// eval/explore_campaign.h); writes explore.json, explore.md, the figure and the shrunk scenes.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <set>
#include <string>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/explore_campaign.h"
#include "comparisons/output/explore_page.h"
#include "comparisons/scene/scene_file.h"
#include "engine/format.h"

namespace fs = std::filesystem;

namespace rbx {

namespace {

// `--bench`: the sampling's throughput, printed.
int explore_bench(const ExploreSettings& set, const ParallelRun& par) {
  const ExploreThroughput t = explore_throughput(set, par);
  if (!par.root()) return 0;
  const double cores = static_cast<double>(par.ranks()) * par.threads();
  std::cout << "rbx explore --bench: " << t.done << " samples (" << t.left_out
            << " with a hull of 100+ points left out) through exact";
  for (const std::string& n : t.backends) std::cout << ", " << n;
  std::cout << " in " << fmt_num(t.seconds, 4) << " s on " << par.ranks() << " rank(s) x "
            << par.threads() << " thread(s): " << fmt_num(t.done / t.seconds * 60.0, 4)
            << " samples/min, " << fmt_num(t.done / t.seconds * 60.0 / cores, 4)
            << " per core per minute\n";
  return 0;
}

// explore.json, the shrunk scenes (replacing the folder's old ones), the figure and explore.md.
void write_explore(const fs::path& out, const ExploreCampaign& c, bool figure_wanted) {
  fs::create_directories(out / "scenes");
  for (const auto& f : fs::directory_iterator(out / "scenes"))
    if (f.path().extension() == ".toml") fs::remove(f.path());
  for (const auto& [file, text] : c.scenes) write_text((out / file).string(), text);
  write_json((out / "explore.json").string(), c.result);
  // The figure draws the contact kind's error distributions; the other kinds' pages give theirs
  // as percentiles in their tables.
  const bool figure =
      figure_wanted && c.summary.kind == "contact" && draw_explore_figure(out.string());
  write_text((out / "explore.md").string(), explore_markdown(c.summary, figure));
}

}  // namespace

int explore_command(const ExploreOptions& opt) {
  ParallelRun par(opt.threads);
  if (opt.count <= 0)
    throw InputError("rbx explore: --count: must be > 0, got " + std::to_string(opt.count));
  const std::set<std::string> kinds = {"contact", "distance", "impact", "landing",
                                       "slide",   "tunnel",   "toi"};
  if (!kinds.count(opt.kind))
    throw InputError(
        "rbx explore: --kind: must be contact, distance, impact, landing, slide, tunnel or toi, "
        "got '" +
        opt.kind + "'");
  ExploreSettings set;
  set.kind = opt.kind;
  set.seed = opt.seed;
  set.count = opt.count;
  set.backends = opt.backends;
  set.shrink_budget = opt.shrink_budget;
  for (size_t at = 0; at < opt.shapes.size();) {
    const size_t comma = std::min(opt.shapes.find(',', at), opt.shapes.size());
    set.shapes.push_back(opt.shapes.substr(at, comma - at));
    at = comma + 1;
  }
  check_shape_pairs(set.shapes, set.kind);
  if (opt.bench) return explore_bench(set, par);

  const ExploreCampaign c = run_explore(set, par);
  if (!par.root()) return std::atoi(par.broadcast("").c_str());
  const fs::path out = opt.out.empty() ? fs::path("reports/explore") : fs::path(opt.out);
  write_explore(out, c, !opt.no_figure);
  std::cout << "rbx explore: " << opt.count << " samples"
            << (set.shapes.empty() ? std::string()
                                   : " (" + std::to_string(c.result.value("samples_kept", 0L)) +
                                         " of the shapes " + opt.shapes + ", the rest left out)")
            << ", " << c.groups << " disagreement groups, " << c.scenes.size() << " scenes ("
            << c.reproduced << " reproduced by the harness) in "
            << fmt_num(c.sampling_s + c.shrinking_s, 3) << " s on " << par.ranks() << " rank(s) x "
            << par.threads() << " thread(s) -> " << out.string() << "/explore.{json,md}\n";
  // Samples that could not be made are said, never silently left out; none made at all is a
  // failed run.
  if (c.invalid > 0)
    std::cerr << "rbx explore: " << c.invalid << " of " << opt.count
              << " samples could not be made (first: " << c.first_invalid << ")\n";
  int code = c.invalid == opt.count ? 1 : 0;
  try {
    if (!opt.baseline.empty()) {
      int worse = 0;
      for (const std::string& line : explore_regressions(c.result, opt.baseline, worse))
        std::cout << "  " << line << "\n";
      std::cout << "rbx explore: "
                << (worse ? std::to_string(worse) + " regressions" : "no regression") << " against "
                << opt.baseline << "\n";
      code = std::max(code, worse ? 1 : 0);
    }
  } catch (const InputError&) {
    par.broadcast("2");  // the other ranks end with the same exit code
    throw;
  }
  par.broadcast(std::to_string(code));
  return code;
}

}  // namespace rbx
