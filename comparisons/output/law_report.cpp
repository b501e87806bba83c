#include "comparisons/output/law_report.h"

#include <algorithm>
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

// A row of a backend that reported no impulses: what its events' depths gave, if anything.
std::string unreported_cell(const LawRow& row) {
  if (row.penetration_only < 0) return "impulses not reported";
  return "impulses not reported; from its events, " + fmt_num(row.penetration_only, 2) +
         " penetration";
}

// The law of a row's largest relative residual.
int top_law(const LawRow& row) {
  int top = 0;
  for (int l = 1; l < kLaws; ++l)
    if (row.relative[l] > row.relative[top]) top = l;
  return top;
}

// "RELATIVE LAW" of a row's largest relative residual; "no contact" when it scored none.
std::string worst_cell(const LawRow& row) {
  if (row.contacts == 0) return "no contact";
  const int top = top_law(row);
  return fmt_num(row.relative[top], 2) + " " + to_string(kAllLaws[top]);
}

// What each residual measures and how a cell reads (both pages).
const char* kLawsIntro =
    "Where no closed form exists, whether each backend obeys the laws of rigid contact, at "
    "every contact point of every step of its run at the scene's step (docs/contact_laws.md), "
    "from the impulses the library itself reports (Bullet's manifold points, ODE's joint "
    "feedback, MuJoCo's contact forces, the custom engine's solved points) and the bodies' "
    "velocities before and after the step: **penetration** at detection (m); **pulling**, a "
    "negative normal impulse (N s); **complementarity**, a pushing contact that does not leave "
    "at Newton's speed e times its approach, normal impulse times the speed it misses (J); "
    "**cone**, friction beyond mu times the normal impulse (N s); **dissipation**, a sliding "
    "contact's friction not at the cone's edge against its slip, the power it fails to remove "
    "times the step (J). *Relative*: a residual divided by its scene's scale (the smallest "
    "moving body's size; its mass times the fastest initial speed, or the speed of a fall "
    "through that size; that times the speed again). A soft contact (MuJoCo) penetrates and "
    "pushes while it separates by design: its residuals are its model's, not round-off. "
    "Numbers: `laws.csv`.";

}  // namespace

std::string contact_laws_markdown(const std::vector<Scene>& scenes,
                                  const std::vector<SceneEvaluation>& evs,
                                  const std::vector<std::string>& backends,
                                  const std::string& report_dir, bool figures_ok) {
  const std::vector<LawRow> rows = law_rows(scenes, evs, backends);
  if (rows.empty()) return "";
  std::vector<std::string> families;
  for (const LawRow& r : rows)
    if (std::find(families.begin(), families.end(), r.family) == families.end())
      families.push_back(r.family);
  std::ostringstream md;
  md << "## Contact laws\n\n"
     << kLawsIntro
     << " Each cell: the largest relative residual over the family's scenes and its law; "
        "details.md has every law in its own unit per family and per scene.\n\n";
  std::vector<std::string> header = {"backend"};
  for (const std::string& f : families) header.push_back(md_escape(f));
  Table t(header);
  for (const std::string& b : backends) {
    std::vector<std::string> cells = {md_escape(b)};
    bool any = false;
    for (const std::string& f : families) {
      std::string cell = "—";
      for (const LawRow& r : rows)
        if (r.backend == b && r.family == f) {
          cell = r.scenes == 0 ? unreported_cell(r) : worst_cell(r);
          any = true;
        }
      cells.push_back(cell);
    }
    if (any) t.add(cells);
  }
  md << t.markdown() << "\n";
  for (const std::string& f : families) {
    const std::string file = "figures/contact_laws_" + f + ".png";
    if (figures_ok && std::filesystem::exists(std::filesystem::path(report_dir) / file))
      md << "![contact laws, " << md_escape(f) << "](" << md_url(file) << ")\n\n";
  }
  return md.str();
}

std::string contact_laws_details_markdown(const std::vector<Scene>& scenes,
                                          const std::vector<SceneEvaluation>& evs,
                                          const std::vector<std::string>& backends) {
  const std::vector<LawRow> rows = law_rows(scenes, evs, backends);
  if (rows.empty()) return "";
  std::ostringstream md;
  md << "## Contact laws\n\n"
     << kLawsIntro
     << " Each cell: the worst over the family's scenes (the median of the scenes' medians); "
        "*worst relative*: the largest relative residual, its law and scene.\n\n";
  for (size_t k = 0; k < rows.size();) {
    size_t end = k;
    while (end < rows.size() && rows[end].family == rows[k].family) ++end;
    md << "### Contact laws: " << md_escape(rows[k].family) << "\n\n";
    Table t({"backend", "scenes", "points", "penetration (m)", "pulling (N s)",
             "complementarity (J)", "cone (N s)", "dissipation (J)", "worst relative"});
    for (size_t r = k; r < end; ++r) {
      const LawRow& row = rows[r];
      if (row.scenes == 0) {
        t.add({md_escape(row.backend), std::to_string(row.unmeasured), "—", unreported_cell(row),
               "—", "—", "—", "—", "—"});
        continue;
      }
      std::vector<std::string> cells = {md_escape(row.backend), std::to_string(row.scenes),
                                        std::to_string(row.contacts)};
      for (int l = 0; l < kLaws; ++l) cells.push_back(worst_median(row.worst[l], row.median[l]));
      cells.push_back(worst_cell(row) + ", " + md_escape(row.worst_scene[top_law(row)]));
      t.add(cells);
    }
    md << t.markdown() << "\n";
    k = end;
  }
  md << scene_laws_markdown(scenes, evs, backends);
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
      if (!s.measured || s.contacts == 0) continue;
      std::vector<std::string> cells = {md_escape(evs[i].family + "/" + scenes[i].name),
                                        md_escape(b), std::to_string(s.contacts)};
      for (int l = 0; l < kLaws; ++l) cells.push_back(worst_median(s.worst[l], s.median[l]));
      t.add(cells);
    }
  if (t.size() == 0) return "";
  return "### Contact laws per scene\n\nEach law's residual, worst (median) over every contact "
         "point of every step, in its own unit; scenes where a backend scored no contact point "
         "are left out.\n\n" +
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
      if (!s.measured || s.contacts == 0) continue;  // nothing scored: no row to plot
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
