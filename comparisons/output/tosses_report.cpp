// The report's "Real impacts" section: the tosses study's tables, CSV files, replays and figures.
#include "comparisons/output/tosses_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "comparisons/eval/trajectory.h"
#include "comparisons/output/figure_script.h"
#include "comparisons/output/scorecard.h"
#include "comparisons/output/view_page.h"
#include "comparisons/scene/repo_path.h"

namespace fs = std::filesystem;

namespace rbx {

Table toss_results_table(const std::vector<BackendTosses>& rs, bool markdown) {
  Table t({"rank", "backend", "e", "mu", "softness", "params", "tosses",
           "position err (widths) med / mean / p90", "angle err (deg) med / mean / p90",
           "final position err med / mean / p90", "run time (s)", "status"});
  auto triple = [](const Spread& s, int d) {
    return fmt_num(s.median, d) + " / " + fmt_num(s.mean, d) + " / " + fmt_num(s.p90, d);
  };
  int rank = 0;
  for (size_t i : toss_ranking(rs)) {
    const BackendTosses& r = rs[i];
    std::vector<double> pos, ang, fin;
    for (const TossErrors& e : r.tosses) {
      pos.push_back(e.position);
      ang.push_back(e.orientation_deg);
      fin.push_back(e.final_position);
    }
    std::string status = to_string(r.status);
    if (!r.message.empty()) status += markdown ? ": " + r.message : "";
    // A backend that ignores friction shows none, not the mu it was handed.
    const Backend* b = find_backend(r.name);
    const std::string mu =
        b && !b->friction ? "none (frictionless)" : fmt_num(r.params.friction, 3);
    // The contact softness run: the fitted values, else the backend's own (rbx's settings).
    std::string soft = soft_text(r.params);
    if (soft.empty() && b && !b->soft.parameters.empty()) {
      // Written as the fitted values are: three digits would show MuJoCo's 0.9999 as 1.
      ContactParams own;
      for (const SoftParameter& p : b->soft.parameters) own.soft.emplace_back(p.name, p.value);
      soft = "own: " + soft_text(own);
    }
    t.add({std::to_string(++rank), r.name, fmt_num(r.params.restitution, 3), mu,
           soft.empty() ? "-" : soft, r.params_source, std::to_string(r.tosses.size()),
           triple(spread_of(pos), 3), triple(spread_of(ang), 3), triple(spread_of(fin), 3),
           fmt_num(r.runtime_s, 3), status});
  }
  return t;
}

namespace {

// Per-toss errors (the distribution figure).
void write_per_toss_csv(const fs::path& out, const TossEvaluation& ev) {
  std::ostringstream per;
  per << "params,backend,toss,position_error,orientation_error_deg,final_position_error\n";
  for (const auto* set : {&ev.stored, &ev.published})
    for (const BackendTosses& r : *set)
      for (const TossErrors& e : r.tosses)
        per << (set == &ev.stored ? "stored" : "published") << "," << r.name << "," << e.toss_id
            << "," << fmt_num(e.position, 9) << "," << fmt_num(e.orientation_deg, 9) << ","
            << fmt_num(e.final_position, 9) << "\n";
  write_text((out / "tosses_per_toss.csv").string(), per.str());
}

// Median position error over tosses at each sample time (what the error is made of).
void write_error_time_csv(const fs::path& out, const TossEvaluation& ev) {
  const double rate = CubeTossModel{}.sample_rate;
  std::ostringstream over;
  over << "backend,t,median_position_error,tosses\n";
  for (const BackendTosses& r : ev.stored) {
    for (size_t i = 0;; ++i) {
      std::vector<double> v;
      for (const TossErrors& e : r.tosses)
        if (i < e.position_by_sample.size()) v.push_back(e.position_by_sample[i]);
      if (v.size() * 2 < r.tosses.size() || v.empty()) break;  // at least half the tosses
      over << r.name << "," << fmt_num((i + 1) / rate, 6) << "," << fmt_num(spread_of(v).median, 6)
           << "," << v.size() << "\n";
    }
  }
  write_text((out / "tosses_error_time.csv").string(), over.str());
}

// The picked tosses drawn for every backend: their height and angle in tosses_traj.csv and one
// 3-D replay each (every backend's cube, the measured cube as a ghost). Returns the replays'
// file names in pick order ("" : not written).
std::vector<std::string> write_picked_tosses(const fs::path& out, const TossReportStudy& study) {
  const double rate = CubeTossModel{}.sample_rate;
  std::ostringstream traj;
  traj << "pick,toss,source,t,z,angle_deg\n";
  std::vector<std::string> replays;
  const fs::path views = out / "views";
  const std::string& best = study.ev.stored[study.order.front()].name;
  for (const PickedToss& pick : study.picks) {
    // Named copies: the lambda below captures id.
    const std::string& label = pick.label;
    const long id = pick.id;
    const Toss& t = *std::find_if(study.tosses.begin(), study.tosses.end(),
                                  [&](const Toss& x) { return x.id == id; });
    const Quat q0 = t.samples.front().orientation;
    for (const TossSample& s : t.samples)
      traj << label << "," << id << ",measured," << fmt_num(s.time - t.samples.front().time, 6)
           << "," << fmt_num(s.position.z(), 7) << ","
           << fmt_num(rotation_angle_deg(q0, s.orientation), 6) << "\n";
    const std::vector<std::pair<std::string, TossRun>>& runs = pick.runs;
    for (const auto& [name, run] : runs) {
      if (run.status != Status::Ok) continue;
      for (size_t i = 0; i < run.track.position.size(); ++i)
        traj << label << "," << id << "," << name << "," << fmt_num(i / rate, 6) << ","
             << fmt_num(run.track.position[i].z(), 7) << ","
             << fmt_num(rotation_angle_deg(q0, run.track.orientation[i]), 6) << "\n";
    }
    try {
      fs::create_directories(views);
      if (!fs::exists(views / "three.min.js"))
        fs::copy_file(three_js_path(), views / "three.min.js");
      const std::string name = "toss_" + label + "_" + std::to_string(id) + ".html";
      const std::string title = "toss " + std::to_string(id) + " (" + label + " of " + best + ")";
      write_text((views / name).string(),
                 view_page(toss_replay_data(t, runs, title), "", "three.min.js"));
      replays.push_back(name);
    } catch (const std::exception& e) {
      std::cerr << "rbx report: toss replay not written: " << e.what() << "\n";
      replays.push_back("");
    }
  }
  write_text((out / "tosses_traj.csv").string(), traj.str());
  return replays;
}

// Figures through matplotlib (the report's own figures need the same python3).
bool draw_tosses_figures(const std::string& out_dir) {
  const fs::path out(out_dir);
  const bool ok =
      run_figure_script("tosses_plots.py", {out_dir}, (out / "tosses_figures.log").string()) == 0;
  if (ok) fs::remove(out / "tosses_figures.log");
  return ok;
}

// What the error is made of: the median over tosses at a few times after release.
std::string error_over_time_table(const TossEvaluation& ev, const std::vector<size_t>& order) {
  const double rate = CubeTossModel{}.sample_rate;
  const std::vector<double> marks = {0.1, 0.2, 0.3, 0.5};  // s
  Table t({"backend", "t = 0.1 s", "0.2 s", "0.3 s", "0.5 s", "last sample",
           "horizontal share at the last sample"});
  for (size_t k : order) {
    const BackendTosses& r = ev.stored[k];
    std::vector<std::string> cells = {r.name};
    auto median_at = [&](const std::vector<double> TossErrors::*series, long i) {
      std::vector<double> v;
      for (const TossErrors& e : r.tosses) {
        const auto& s = e.*series;
        if (s.empty()) continue;
        v.push_back(i < 0 ? s.back() : s[std::min<size_t>(static_cast<size_t>(i), s.size() - 1)]);
      }
      return spread_of(v).median;
    };
    for (double m : marks)
      cells.push_back(
          fmt_num(median_at(&TossErrors::position_by_sample, std::lround(m * rate) - 1), 3));
    const double last = median_at(&TossErrors::position_by_sample, -1);
    cells.push_back(fmt_num(last, 3));
    cells.push_back(fmt_num(median_at(&TossErrors::horizontal_by_sample, -1) / last, 3));
    t.add(cells);
  }
  return t.markdown();
}

}  // namespace

std::string tosses_report_section(const TossReportStudy& study, const std::string& out_dir) {
  if (study.chosen.empty()) return "";
  const std::vector<Toss>& tosses = study.tosses;
  const TossEvaluation& ev = study.ev;
  const fs::path out(out_dir);
  Json doc = toss_evaluation_json(study.data, tosses, study.params_path, ev);
  doc["energy_gain"] = energy_gains_json(study.flagged, tosses.size());
  write_json((out / "tosses.json").string(), doc);
  write_per_toss_csv(out, ev);
  write_error_time_csv(out, ev);
  const std::vector<std::string> replays = write_picked_tosses(out, study);
  const bool figures_ok = draw_tosses_figures(out_dir);
  const BackendTosses& best = ev.stored[study.order.front()];
  const std::vector<PickedToss>& picks = study.picks;
  const std::string& data = study.data;
  const std::string& params_path = study.params_path;

  size_t samples = 0;
  for (const Toss& t : tosses) samples += t.samples.size();
  std::ostringstream md;
  md << "## Real impacts: measured cube tosses\n\n";
  md << tosses.size() << " test tosses (" << samples << " samples) of a real 10.48 cm, 0.37 kg "
     << "cube onto a floor, tracked by motion capture at 148 Hz (ContactNets data, "
     << md_code(data) << "; the split and the source are in the README beside it); "
     << study.flagged.size() << " of its " << study.all_tosses
     << " tosses left out for an energy gain across an impact beyond the tracking noise"
     << energy_gains_list(study.flagged) << ". "
     << "Each toss is simulated from its first measured sample (pose, velocity, angular "
     << "velocity) for its recorded duration, dt = 1/1480 s (10 substeps per sample), and "
     << "compared at every sample: **position error** = mean |p_sim - p_real| over the toss in "
     << "cube widths, **angle error** = mean rotation angle between simulated and measured "
     << "orientation, **final** = the position error at the last (resting) sample. Median / "
     << "mean / 90th percentile over tosses; ranked by the median position error. All "
     << study.chosen.size() << " backends at both parameter sets took " << fmt_num(study.eval_s, 3)
     << " s.\n\n";
  md << "### At each backend's fitted parameters (" << md_code(params_path) << ", fitted on the "
     << "training tosses)\n\n"
     << toss_results_table(ev.stored, true).markdown() << "\n";
  md << "### At the dataset's published parameters (e = 0.125, mu = 0.18)\n\n"
     << "The same parameters for every backend: the difference to the table above is what "
        "fitting buys; what remains is the contact model.\n\n"
     << toss_results_table(ev.published, true).markdown() << "\n";
  md << "Median position error (cube widths) over the tosses at times after release (a toss "
        "already at rest counts with its last sample; the first measured impact comes at 0.115 s "
        "(median; 0.07 to 0.18 s)) and the horizontal (x, y) part of the final error, at the "
        "fitted parameters:\n\n"
     << error_over_time_table(ev, study.order) << "\n";
  if (figures_ok) {
    md << "![toss error distribution](figures/tosses_errors.png)\n\n"
       << "Left: position error per toss, every backend (fitted and published parameters). "
          "Right: the median position error over tosses at each time after release: the first "
          "impact, the tumbling after it and the slide to rest show as the steps of each "
          "curve.\n\n";
    if (!picks.empty())
      md << "![toss trajectories](figures/tosses_trajectories.png)\n\n"
         << "Height of the centre and rotation angle from the release orientation, measured "
            "(black) and simulated, for the best (toss "
         << picks[0].id << "), median (toss " << picks[1].id << ") and worst (toss " << picks[2].id
         << ") toss of the best backend, " << md_code(best.name) << ".\n\n";
    if (replays.size() == 3 && !replays[0].empty())
      md << "3-D replays of these tosses, every backend side by side with the measured cube as "
            "a grey ghost: [best](views/"
         << replays[0] << "), [median](views/" << replays[1] << "), [worst](views/" << replays[2]
         << ").\n\n";
  } else {
    md << "(figures not drawn: python3 with matplotlib missing or tosses_plots.py failed, see "
          "tosses_figures.log)\n\n";
  }
  return md.str();
}

}  // namespace rbx
