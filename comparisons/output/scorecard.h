// The scorecard that opens report.md: one row per backend and scene family (scenes run, how many
// within tolerance, median and worst error against the truth, median run time per step or
// query), then the measured causes of each backend's failures, one line each, with the scenes.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/metrics.h"  // median_of, for the scorecard's users
#include "comparisons/scene/scene.h"

namespace rbx {

/// The file-name slug of a scene in a report: FAMILY_STEM (figures, replay pages).
std::string scene_slug(const std::string& family, const std::string& file);

/// Text safe in Markdown (table cells, link text, a paragraph): \ ` * _ [ ] < > | # & ~ escaped,
/// and a list marker that would open the text ("- ", "+ ", "1. ") escaped too; leading spaces
/// and tabs dropped (they would indent it into code); line breaks are spaces.
std::string md_escape(const std::string& s);

/// A relative path as a link's destination in Markdown or HTML: every byte but letters, digits,
/// "-._~/" percent-encoded, so that a scene's file or folder name with a space, a parenthesis, a
/// quote or any other character ends neither the link nor the attribute, and the browser finds
/// the file by its name.
std::string md_url(const std::string& path);

/// Text as one Markdown code span (outside a table): fenced with one backtick more than its
/// longest run of backticks, padded with a space where it starts or ends with one; line breaks
/// are spaces. Shown exactly as written, whatever it holds.
std::string md_code(const std::string& text);

/// What a scorecard row's error measures: a contact query's normal angle and depth, a dynamic
/// run's post-impact velocity, or mass properties. It comes from the scene's checks, so that a
/// folder mixing contact and dynamics scenes gets one row per kind, each in its own unit.
enum class Measure { Contact, Dynamics, Mass };

/// One backend on one scene family and measure: what the scorecard shows.
struct ScoreRow {
  std::string backend, family;
  Measure measure = Measure::Contact;
  int run = 0, within = 0, touching = 0;  // touching: answered with no normal
  /// Per scene with an error against the truth (closed form, `exact` oracle, exact solid):
  /// contact normal angle (deg), velocity error (kinetic-energy norm) or mass relative error.
  std::vector<double> error;
  std::vector<double> depth_error;  // contact: depth error (m), beside `error`
  /// Contact: per scene with an exact patch, the largest coverage_err_rel over its pairs (how
  /// far the backend's points fall short of the patch, relative to the smaller body).
  std::vector<double> coverage;
  /// Run time (s) per query (contact) or per step (dynamics); prebuilt: the library's shapes
  /// built once (its "prebuilt" variant, where it has one).
  std::vector<double> time, prebuilt;
  /// Dynamics: the largest contact-law residual relative to its scene's scale over the scenes
  /// (comparisons/eval/law_residuals.h) and its law; negative when none was measured.
  double law_relative = -1.0;
  std::string law;
  /// Dynamics: per scene of the family with an ensemble (report.md, "Predictability"), the
  /// backend's position amplification.
  std::vector<double> amplification;
  /// The row's cells as text: within tolerance, median and worst error, run time, worst
  /// contact-law residual, predictability (the median amplification), coverage (median and
  /// worst).
  std::string within_text() const, median_text() const, worst_text() const, time_text() const,
      law_text() const, predictability_text() const, coverage_text() const;
};

/// A scene named in a report: FAMILY/NAME and its slug (views/SLUG.html is its replay page).
struct SceneRef {
  std::string name, slug;
};

/// One measured cause of failures of a backend, with the scenes it explains.
struct FailureCause {
  std::string backend, cause;
  std::vector<SceneRef> scenes;
};

/// The scorecard: one row per (backend, family, measure) in which the backend ran a scene,
/// grouped by family and measure in the order the scenes come, and within a group ranked: first
/// the rows with an error against the truth, by median error (contact: normal angle, then
/// depth), then most scenes within tolerance, then worst error, then run time. `causes` gets the
/// measured cause of every failure, per backend in `backends` order.
std::vector<ScoreRow> score_rows(const std::vector<Scene>& scenes,
                                 const std::vector<SceneEvaluation>& evs,
                                 const std::vector<std::string>& backends,
                                 std::vector<FailureCause>* causes = nullptr);

/// The heading of a row's group: the family, and the measure with its unit.
std::string group_title(const ScoreRow& row);

/// The scorecard in Markdown: one ranked table per group (details.md). `timing_budget_s`: the
/// run's HarnessOptions::timing_budget_s, which says what its run times are.
std::string scorecard_markdown(const std::vector<ScoreRow>& rows,
                               double timing_budget_s = HarnessOptions{}.timing_budget_s);

/// The scorecard at a glance (report.md): one table, a row per backend and a column per group,
/// each cell the backend's rank in that group, its median error and its scenes within tolerance
/// of those run. Its length grows with the backends, not with the scenes or the families' rows.
std::string scorecard_matrix_markdown(const std::vector<ScoreRow>& rows);

/// The measured causes of the failures: every cause with every scene, or `compact`, one line
/// per backend with each cause's count and one scene; scenes link their replay pages when
/// `views`.
std::string causes_markdown(const std::vector<FailureCause>& causes, bool compact, bool views);

/// The contact query times in Markdown: per backend, the median over the scenes' queries of the
/// time per query with the library's shapes built in the query (as the backend runs), with them
/// prebuilt (its "prebuilt" variant, where it has one), and the difference, the cost of
/// building them. Empty when no contact query ran. `timing_budget_s`: the run's
/// HarnessOptions::timing_budget_s, which the text states (0: one call per query, said so).
std::string query_time_markdown(const std::vector<SceneEvaluation>& evs,
                                const std::vector<std::string>& backends,
                                double timing_budget_s = HarnessOptions{}.timing_budget_s);

}  // namespace rbx
