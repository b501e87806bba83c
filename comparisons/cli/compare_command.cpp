// `rbx compare SCENE...`: the scene's checks, side by side in the terminal, and the JSON.
#include <iostream>
#include <map>
#include <set>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/harness.h"
#include "comparisons/output/table.h"

namespace rbx {

namespace {

// Metrics as rows (check, pair, name, against) and backends as columns.
void print_side_by_side(std::ostream& out, const SceneEvaluation& ev) {
  std::vector<std::string> columns;
  for (const Metric& m : ev.metrics)
    if (std::find(columns.begin(), columns.end(), m.backend) == columns.end())
      columns.push_back(m.backend);
  if (columns.empty()) return;
  std::vector<std::string> header = {"metric", "against"};
  header.insert(header.end(), columns.begin(), columns.end());
  Table t(header);
  std::vector<std::string> row_keys;
  std::map<std::string, std::map<std::string, double>> cells;
  std::map<std::string, std::string> against;
  for (const Metric& m : ev.metrics) {
    const std::string key = m.check + " " + (m.pair.empty() ? "" : m.pair + " ") + m.name;
    if (!cells.count(key)) row_keys.push_back(key);
    cells[key][m.backend] = m.value;
    against[key] = m.against;
  }
  for (const std::string& key : row_keys) {
    std::vector<std::string> row = {key, against[key]};
    for (const std::string& c : columns)
      row.push_back(cells[key].count(c) ? fmt_num(cells[key][c], 3) : "-");
    t.add(row);
  }
  t.print(out);
}

}  // namespace

int compare_command(const SceneCommandOptions& opt) {
  // Load every scene first: bad input stops the command before anything runs or is written.
  std::vector<Scene> scenes;
  for (const std::string& path : opt.scenes) scenes.push_back(load_scene_for_command(path, opt));
  std::ostream& out = opt.json == "-" ? std::cerr : std::cout;
  HarnessOptions hopt;
  hopt.backends = opt.backends;
  hopt.studies = false;
  Json result;
  result["scenes"] = Json::array();
  int failed = 0;
  for (const Scene& scene : scenes) {
    const SceneEvaluation ev = evaluate_scene(scene, hopt);
    out << "scene: " << scene.name << " (" << scene.file << ")\n";
    for (const std::string& s : scene.input_notes) out << "  input: " << s << "\n";
    Table status({"backend", "status", "message"});
    for (const auto& [name, bj] : ev.json["backends"].items())
      status.add({name, bj["status"].get<std::string>(), bj["message"].get<std::string>()});
    status.print(out);
    print_side_by_side(out, ev);
    for (const std::string& s : ev.disagreements) out << "  disagrees: " << s << "\n";
    for (const std::string& s : ev.deviations) out << "  deviates: " << s << "\n";
    for (const std::string& s : ev.skipped) out << "  left out: " << s << "\n";
    if (scene.expect) {
      if (!ev.expect_checked)
        out << "  [expect]: not checked\n";
      else if (ev.expect_failures.empty())
        out << "  [expect]: passed\n";
      for (const std::string& s : ev.expect_unchecked)
        out << "  [expect] not checked: " << s << "\n";
      for (const std::string& s : ev.expect_failures) out << "  [expect] FAILED: " << s << "\n";
      if (ev.expect_known)
        out << "  [expect] known failure: " << scene.expect->known_failure << "\n";
    }
    out << "\n";
    // A documented limitation of an engine does not fail the command; anything else does.
    const bool passed = ev.expect_failures.empty() || ev.expect_known;
    if (!passed) ++failed;
    Json doc = ev.json;
    doc["passed"] = passed;
    result["scenes"].push_back(std::move(doc));
  }
  result["passed"] = failed == 0;  // the exit code's verdict: 0 when passed
  if (!opt.json.empty()) write_json(opt.json, result);
  return failed > 0 ? 1 : 0;
}

}  // namespace rbx
