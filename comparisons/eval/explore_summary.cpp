// read_explore_summary: explore.json read once into what explore.md shows.
#include "comparisons/eval/explore_summary.h"

#include "comparisons/scene/scene_file.h"  // InputError

namespace rbx {

namespace {

ExplorePercentiles read_percentiles(const Json& e) {
  ExplorePercentiles p;
  p.p50 = e.at("p50").get<double>();
  p.p90 = e.at("p90").get<double>();
  p.p99 = e.at("p99").get<double>();
  p.max = e.at("max").get<double>();
  return p;
}

ExploreGroup read_group(const Json& x) {
  ExploreGroup g;
  g.signature = x.at("signature").get<std::string>();
  g.count = x.at("count").get<long>();
  g.rate = x.at("rate").get<double>();
  if (x.contains("scene") && x["scene"].is_string()) g.scene = x["scene"].get<std::string>();
  if (x.contains("points_before")) {
    g.points_before = x["points_before"].get<int>();
    g.points_after = x.at("points_after").get<int>();
  }
  g.reproduced = x.value("reproduced", false);
  return g;
}

ExploreBackendSummary read_backend(const std::string& name, const Json& b) {
  ExploreBackendSummary s;
  s.name = name;
  s.samples = b.at("samples").get<long>();
  s.disagreements = b.at("disagreements").get<long>();
  s.rate = b.at("rate").get<double>();
  if (b.contains("coverage_misses")) s.coverage_misses = b["coverage_misses"].get<long>();
  for (const auto& [metric, e] : b.at("errors").items()) s.errors[metric] = read_percentiles(e);
  if (b.contains("by_phase_quarter"))
    for (const Json& q : b["by_phase_quarter"])
      s.by_phase_quarter.push_back({q.at("samples").get<long>(), q.at("rate").get<double>()});
  for (const Json& x : b.at("groups")) s.groups.push_back(read_group(x));
  return s;
}

}  // namespace

const ExplorePercentiles& ExploreBackendSummary::error(const std::string& metric) const {
  const auto it = errors.find(metric);
  if (it == errors.end())
    throw InputError("explore.json: backend " + name + " has no \"" + metric + "\" errors");
  return it->second;
}

ExploreSummary read_explore_summary(const Json& j) {
  ExploreSummary s;
  try {
    s.kind = j.at("kind").get<std::string>();
    s.seed = j.at("seed").get<uint64_t>();
    s.count = j.at("count").get<long>();
    if (!j.at("backends").is_object())
      throw InputError("explore.json: \"backends\" is not an object");
  } catch (const Json::exception& e) {
    throw InputError(std::string("explore.json: ") + e.what());
  }
  for (const auto& [name, b] : j["backends"].items()) {
    try {
      s.backends.push_back(read_backend(name, b));
    } catch (const Json::exception& e) {
      throw InputError("explore.json: backend " + name + ": " + e.what());
    }
  }
  return s;
}

}  // namespace rbx
