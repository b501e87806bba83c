#include "comparisons/output/law_report.h"

#include <filesystem>
#include <sstream>

#include "comparisons/eval/law_residuals.h"
#include "comparisons/output/scorecard.h"
#include "comparisons/output/table.h"

namespace rbx {

namespace {

// "worst (median)" in the law's unit.
std::string worst_median(double worst, double median) {
  return fmt_num(worst, 2) + " (" + fmt_num(median, 2) + ")";
}

}  // namespace

std::string contact_laws_markdown(const std::vector<Scene>& scenes,
                                  const std::vector<SceneEvaluation>& evs,
                                  const std::vector<std::string>& backends,
                                  const std::string& report_dir, bool figures_ok) {
  const std::vector<LawRow> rows = law_rows(scenes, evs, backends);
  if (rows.empty()) return "";
  std::ostringstream md;
  md << "## Contact laws\n\n"
        "Where no closed form exists, whether each backend obeys the laws of rigid contact, at "
        "every contact point of every step of its run at the scene's step "
        "(docs/contact_laws.md), from the impulses the library itself reports (Bullet's "
        "manifold points, ODE's joint feedback, MuJoCo's contact forces, the custom engine's "
        "solved points) and the bodies' velocities before and after the step: "
        "**penetration** at detection (m); **pulling**, a negative normal impulse (N s); "
        "**complementarity**, a pushing contact that does not leave at Newton's speed e times "
        "its approach, normal impulse times the speed it misses (J); **cone**, friction beyond "
        "mu times the normal impulse (N s); **dissipation**, a sliding contact's friction not "
        "at the cone's edge against its slip, the power it fails to remove times the step (J). "
        "Each cell: the worst over the family's scenes (the median of the scenes' medians). "
        "*Worst relative*: the largest residual divided by the scene's scale (the smallest "
        "moving body's size, its mass times the fastest initial speed, or the speed of a fall "
        "through that size, and that times the speed again), with its law and scene. A soft "
        "contact (MuJoCo) penetrates and pushes while it separates by design: its residuals are "
        "its model's, not round-off. Numbers: `laws.csv`.\n\n";
  for (size_t k = 0; k < rows.size();) {
    size_t end = k;
    while (end < rows.size() && rows[end].family == rows[k].family) ++end;
    md << "### " << md_escape(rows[k].family) << "\n\n";
    Table t({"backend", "scenes", "points", "penetration (m)", "pulling (N s)",
             "complementarity (J)", "cone (N s)", "dissipation (J)", "worst relative"});
    for (size_t r = k; r < end; ++r) {
      const LawRow& row = rows[r];
      if (row.scenes == 0) {
        t.add({md_escape(row.backend), std::to_string(row.unmeasured), "—",
               "impulses not reported", "—", "—", "—", "—", "—"});
        continue;
      }
      std::vector<std::string> cells = {md_escape(row.backend), std::to_string(row.scenes),
                                        std::to_string(row.contacts)};
      int top = 0;
      for (int l = 0; l < kLaws; ++l) {
        cells.push_back(worst_median(row.worst[l], row.median[l]));
        if (row.relative[l] > row.relative[top]) top = l;
      }
      cells.push_back(fmt_num(row.relative[top], 2) + " " + to_string(kAllLaws[top]) + ", " +
                      md_escape(row.worst_scene[top]));
      t.add(cells);
    }
    md << t.markdown() << "\n";
    const std::string file = "figures/contact_laws_" + rows[k].family + ".png";
    if (figures_ok && std::filesystem::exists(std::filesystem::path(report_dir) / file))
      md << "![contact laws, " << md_escape(rows[k].family) << "](" << file << ")\n\n";
    k = end;
  }
  return md.str();
}

std::string scene_laws_markdown(const std::vector<Scene>& scenes,
                                const std::vector<SceneEvaluation>& evs,
                                const std::vector<std::string>& backends) {
  Table t({"scene", "backend", "points", "penetration (m)", "pulling (N s)", "complementarity (J)",
           "cone (N s)", "dissipation (J)"});
  for (size_t i = 0; i < evs.size() && i < scenes.size(); ++i)
    for (const std::string& b : backends) {
      const SceneLaws s = scene_laws(scenes[i], evs[i], b);
      if (!s.measured) continue;
      std::vector<std::string> cells = {md_escape(evs[i].family + "/" + scenes[i].name),
                                        md_escape(b), std::to_string(s.contacts)};
      for (int l = 0; l < kLaws; ++l) cells.push_back(worst_median(s.worst[l], s.median[l]));
      t.add(cells);
    }
  if (t.size() == 0) return "";
  return "## Contact laws per scene\n\nEach law's residual, worst (median) over every contact "
         "point of every step, in its own unit (report.md, \"Contact laws\", says what each "
         "measures).\n\n" +
         t.markdown() + "\n";
}

std::string laws_csv(const std::vector<Scene>& scenes, const std::vector<SceneEvaluation>& evs,
                     const std::vector<std::string>& backends) {
  std::ostringstream csv;
  csv << "scene,family,backend,law,unit,worst,median,scale,relative,contacts\n";
  for (size_t i = 0; i < evs.size() && i < scenes.size(); ++i) {
    const LawScales scales = law_scales(scenes[i]);
    for (const std::string& b : backends) {
      const SceneLaws s = scene_laws(scenes[i], evs[i], b);
      if (!s.measured) continue;
      for (Law law : kAllLaws) {
        const int l = static_cast<int>(law);
        csv << csv_escape(scenes[i].name) << "," << csv_escape(evs[i].family) << "," << b << ","
            << to_string(law) << "," << law_unit(law) << "," << fmt_num(s.worst[l], 17) << ","
            << fmt_num(s.median[l], 17) << "," << fmt_num(scales.of(law), 17) << ","
            << fmt_num(s.relative[l], 17) << "," << s.contacts << "\n";
      }
    }
  }
  return csv.str();
}

}  // namespace rbx
