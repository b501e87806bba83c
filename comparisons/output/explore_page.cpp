// explore.md and the error-distribution figure of an explore campaign (comparisons/eval/
// explore_campaign.h).
#include "comparisons/output/explore_page.h"

#include <filesystem>
#include <sstream>

#include "comparisons/output/figure_script.h"
#include "comparisons/output/table.h"
#include "comparisons/scene/repo_path.h"
#include "engine/format.h"

namespace fs = std::filesystem;

namespace rbx {

namespace {

// The disagreement groups of an explore result, one row each (every kind).
std::string groups_table(const ExploreSummary& s) {
  Table g({"backend", "signature", "count", "rate", "scene", "points", "reproduced"});
  for (const ExploreBackendSummary& b : s.backends)
    for (const ExploreGroup& x : b.groups)
      g.add({b.name, x.signature, std::to_string(x.count), fmt_num(x.rate, 3),
             x.scene ? *x.scene : std::string("-"),
             x.points_before ? std::to_string(*x.points_before) + " -> " +
                                   std::to_string(x.points_after.value_or(0))
                             : std::string("-"),
             x.reproduced ? "yes" : "no"});
  return g.markdown();
}

// A metric's p50 / p90 / p99 over a backend's samples, `digits` significant digits.
std::string three(const ExploreBackendSummary& b, const char* m, int digits = 2) {
  const ExplorePercentiles& e = b.error(m);
  return fmt_num(e.p50, digits) + " / " + fmt_num(e.p90, digits) + " / " + fmt_num(e.p99, digits);
}

// The table of disagreement rates by the quarter of its step the first contact falls in.
std::string phase_table(const ExploreSummary& s) {
  Table ph({"backend", "0-25 %", "25-50 %", "50-75 %", "75-100 %"});
  for (const ExploreBackendSummary& b : s.backends) {
    std::vector<std::string> row = {b.name};
    for (const ExplorePhaseQuarter& q : b.by_phase_quarter)
      row.push_back(fmt_num(q.rate, 3) + " (" + std::to_string(q.samples) + ")");
    ph.add(row);
  }
  return ph.markdown();
}

// A backend's first four cells: name, samples, disagreements, rate.
std::vector<std::string> counts(const ExploreBackendSummary& b) {
  return {b.name, std::to_string(b.samples), std::to_string(b.disagreements), fmt_num(b.rate, 3)};
}

// `head` with `tail` appended.
std::vector<std::string> cells(std::vector<std::string> head,
                               const std::vector<std::string>& tail) {
  head.insert(head.end(), tail.begin(), tail.end());
  return head;
}

std::string markdown_impact(const ExploreSummary& s) {
  std::ostringstream o;
  o << "# rbx explore: " << s.count << " random single-point impacts, seed " << s.seed << "\n\n"
    << "Every sample is one body (a box or a hull of 4 to 60 points) hitting a box, free or "
       "static, at one vertex on a face, with restitution e in [0.2, 1], no friction, no "
       "gravity, first contact 2 to 5 steps ahead at a random phase of its step. The closed form "
       "(single-point impulse at the exact oracle's point and normal, then torque-free flight) "
       "is the truth. A disagreement: a status error, no impulse at all (missed), a momentum "
       "error above 0.1 % in the energy norm (impulse), or a velocity error above it with the "
       "momenta right (spin: the free rotation after the impact).\n\n## Backends\n\n";
  Table t({"backend", "samples", "disagreements", "rate", "velocity err p50/p90/p99",
           "momentum err p50/p90/p99"});
  for (const ExploreBackendSummary& b : s.backends)
    t.add(cells(counts(b), {three(b, "velocity_err_ke"), three(b, "momentum_err_ke")}));
  o << t.markdown();
  o << "\n## Disagreement rate by the phase of the contact within its step\n\nThe first contact "
       "falls at this fraction of the step that detects it (0 %: at the step's start, so the "
       "bodies overlap by a whole step of approach when it is seen).\n\n";
  o << phase_table(s);
  o << "\n## Disagreement groups\n\nSignature: backend, shape classes of A and B (static: B "
       "is static), the contact's features, the kind of error. Each group's first sample was "
       "shrunk to the scene named; `reproduced` says whether `rbx compare` shows the velocity "
       "error on it.\n\n";
  o << groups_table(s);
  return o.str();
}

std::string markdown_landing(const ExploreSummary& s) {
  std::ostringstream o;
  o << "# rbx explore: " << s.count << " random flat landings with friction, seed " << s.seed
    << "\n\n"
    << "Every sample is a box (sides 0.2 to 2 m, mass 0.1 to 10 kg, any yaw) landing flat on a "
       "static floor, e = 0, mu in [0.1, 1], falling at 0.2 to 2 m/s and sliding at 0.05 to "
       "1.5 m/s, under gravity, first touch 2 to 5 steps ahead at a random phase of its step; "
       "its height is drawn so that it cannot tip (mu sz <= 0.8 min(sx, sy)). The closed form "
       "(landing impulse J = m vn, friction impulse min(mu J, m |v_h|), a slide decelerating at "
       "mu g to rest, no turn) is the truth at the end of the run, 0.1 s or more after the rest. "
       "A disagreement: a status error, a turn above 1e-3 rad (turn), or a resting centre more "
       "than 1 mm from the closed form, horizontally (position; late_landing where the offset is "
       "the slide of the rest of the touching step, (|v_h| - |v_h'|) (1 - phase) dt along the "
       "launch, within the slide's own discretisation: the landing resolved at the step after "
       "the touch, no time of impact; or, read from the run's steps, a landing resolved after "
       "its touching step whose friction was mu times its own normal impulse and after which "
       "the box slid to rest as Coulomb's slide does: found deeper, it pushed back harder than "
       "m vn and took more of the slide); any of these is named deep_contact where the library "
       "reported a contact deeper than a tenth of the box's smallest side (its collider's "
       "answer: no landing box goes so deep), else lift_off where the box's centre rose more "
       "than 0.1 mm off the floor after its first touch (the closed form's box never leaves "
       "it; docs/references.md says whose model does this), and a turn or position miss "
       "cone_excess where "
       "the friction the library applied beyond the Coulomb cone (measured on its own impulses, "
       "docs/contact_laws.md) gave at least half the turn or the part of it past the mark, or "
       "moved the stop past the mark. Time "
       "to rest: the first step "
       "whose horizontal speed is below 1 mm/s, the box moving less than 0.1 mm after it, read "
       "from every step (one step's resolution); reported, not marked. Velocity error: the final "
       "velocities in the energy "
       "norm against the initial kinetic energy.\n\n## Backends\n\n";
  Table t({"backend", "samples", "disagreements", "rate", "position err p50/p90/p99 (m)",
           "turn p50/p90/p99 (rad)", "rest time err p50/p99 (s)", "velocity err p99"});
  for (const ExploreBackendSummary& b : s.backends) {
    const ExplorePercentiles& rest = b.error("rest_time_err_s");
    t.add(cells(counts(b), {three(b, "position_err_m"), three(b, "turn_rad"),
                            fmt_num(rest.p50, 2) + " / " + fmt_num(rest.p99, 2),
                            fmt_num(b.error("velocity_err_ke").p99, 2)}));
  }
  o << t.markdown();
  o << "\n## Disagreement rate by the phase of the first touch within its step\n\nThe first "
       "touch falls at this fraction of the step that detects it (0 %: at the step's start).\n\n";
  o << phase_table(s);
  o << "\n## Disagreement groups\n\nSignature: backend, box-floor, whether the base slides on "
       "after the landing (slides) or the landing stops it (sticks), the kind of error. Each "
       "group's first sample was shrunk to the scene named; `reproduced` says whether `rbx "
       "compare` shows the same final position or turn on it.\n\n";
  o << groups_table(s);
  return o.str();
}

std::string markdown_slide(const ExploreSummary& s) {
  std::ostringstream o;
  o << "# rbx explore: " << s.count << " random slides with friction, seed " << s.seed << "\n\n"
    << "Every sample is a box (sides 0.2 to 2 m, mass 0.1 to 10 kg, any yaw) resting on a static "
       "floor (2 samples in 5, 1 µm into it: zero depth rounds to some corners off) or incline "
       "(any heading, up to where mu cos(theta) - sin(theta) = "
       "0.1), e = 0, mu in [0.1, 1], launched along the surface at 0.05 to 1.5 m/s (on an "
       "incline down or up its fall line) or left at rest on the incline; its height is drawn so "
       "that it cannot tip (mu sz <= 0.8 min(sx, sy)). The closed form (deceleration mu g on a "
       "floor, g (mu cos(theta) -/+ sin(theta)) down or up an incline, stop distance v^2 / 2a "
       "along the launch, time to rest v / a, static friction holding it after, no turn) is "
       "the truth; the run goes on 0.2 s past the rest. A disagreement: a status error, a turn "
       "above 1e-3 rad (turn), a resting centre more than 1 mm from the closed form along the "
       "surface (position), or a time to rest more than 3 ms off (rest_time: the first step "
       "whose speed along the surface is below 1 mm/s, the box moving less than 0.1 mm after it, "
       "read from every step); any of these is named deep_contact where the library reported a "
       "contact deeper than a tenth of the box's smallest side (its collider's answer: no "
       "resting box goes so deep), else lift_off where the box's centre rose more than 0.1 mm "
       "off its surface on the way (the closed form's box never leaves it; docs/references.md says "
       "whose model does this), or, for a rest_time miss, rose more than 0.01 mm and its speed "
       "along the normal at its last sliding step accounts for the late rest to within 3 ms "
       "(without the friction of that missing push, it stops mu |v_n| / a later); a turn or "
       "position miss is named cone_excess where the "
       "friction the library applied beyond the Coulomb cone (measured on its own impulses, "
       "docs/contact_laws.md; Bullet leaves it at points with no normal impulse) gave at least "
       "half the turn or the part of it past the mark, or moved the stop by what puts it past the "
       "mark. Velocity error: "
       "the final velocities in the energy norm against the launch's kinetic energy (a 1 m/s "
       "slide's for a box left at rest).\n\n## Backends\n\n";
  Table t({"backend", "samples", "disagreements", "rate", "position err p50/p90/p99 (m)",
           "turn p50/p90/p99 (rad)", "rest time err p50/p90/p99 (s)", "velocity err p99"});
  for (const ExploreBackendSummary& b : s.backends)
    t.add(cells(counts(b),
                {three(b, "position_err_m"), three(b, "turn_rad"), three(b, "rest_time_err_s"),
                 fmt_num(b.error("velocity_err_ke").p99, 2)}));
  o << t.markdown();
  o << "\n## Disagreement groups\n\nSignature: backend, box-floor or box-incline, the case "
       "(floor, down, up, sticks), the kind of error. Each group's first sample was shrunk to the "
       "scene named; `reproduced` says whether `rbx compare` shows the same final position or "
       "turn on it (a time to rest: the written scene's own run).\n\n";
  o << groups_table(s);
  return o.str();
}

std::string markdown_tunnel(const ExploreSummary& s) {
  std::ostringstream o;
  o << "# rbx explore: " << s.count << " random fast projectiles at thin walls, seed " << s.seed
    << "\n\n"
    << "Every sample is a box (sides 0.05 to 0.5 m, mass 0.1 to 10 kg) flying face-on at a static "
       "wall 1 to 10 cm thick, facing any way, with restitution e in [0, 1], no friction, no "
       "gravity, a tangential speed up to half the normal one, and a normal speed that carries it "
       "0.2 to 20 times the wall's thickness plus its own depth in one step (log-uniform: "
       "`fast` above 1, where a step can jump the wall), first touch 2 to 5 steps ahead at a "
       "random phase of its step. The closed form (the normal velocity reversed times e, the "
       "tangential kept, no spin, the box on the near side) is the truth 10 steps after the "
       "contact's step. A disagreement: a status error, a centre past the wall's near face at "
       "the end (tunnel: through the wall or inside it), or a velocity error above 0.1 % in the "
       "energy norm (velocity). Libraries with continuous collision (Bullet's, as the backend "
       "table says) should not tunnel; those without it can.\n\n## Backends\n\n";
  Table t({"backend", "samples", "disagreements", "rate", "velocity err p50/p90/p99",
           "position err p50/p90/p99 (m)"});
  for (const ExploreBackendSummary& b : s.backends)
    t.add(cells(counts(b), {three(b, "velocity_err_ke"), three(b, "position_err_m")}));
  o << t.markdown();
  o << "\n## Disagreement rate by the phase of the first touch within its step\n\n";
  o << phase_table(s);
  o << "\n## Disagreement groups\n\nSignature: backend, box-wall, whether one step can carry "
       "the box past the wall (fast) or not (slow), the kind of error. Each group's first sample "
       "was shrunk to the scene named; `reproduced` says whether `rbx compare` shows the "
       "velocity error on it.\n\n";
  o << groups_table(s);
  return o.str();
}

std::string markdown_distance(const ExploreSummary& s) {
  std::ostringstream o;
  o << "# rbx explore: " << s.count << " random separated pairs, seed " << s.seed << "\n\n"
    << "Every sample is a pair of the contact kind's shapes (boxes, hulls of 4 to 2,000 points, "
       "slivers; size ratios up to 1e3) in its poses, moved apart along the exact closest pair's "
       "direction to a gap drawn log-uniformly from 1e-9 to 10 times the smaller body's size "
       "(hair: below 1e-4 of it, near: below 0.1, far), each backend's distance query checked "
       "against the exact oracle as `rbx distance` checks it. A disagreement is a status error, "
       "an overlap reported for a pair that is apart, a distance off by more than 1e-6 of the "
       "true distance, or witness points more than that from a closest pair (errors relative to "
       "the true distance, at least 1e-8 of the pair's extent from the origin; "
       "docs/distance.md).\n\n";
  o << "## Backends\n\n";
  Table t({"backend", "samples", "disagreements", "rate", "distance p50/p90/p99 (rel)",
           "witness p50/p90/p99 (rel)", "worst distance (rel)"});
  for (const ExploreBackendSummary& b : s.backends)
    t.add(cells(counts(b), {three(b, "distance_err_rel"), three(b, "witness_err_rel"),
                            fmt_num(b.error("distance_err_rel").max, 2)}));
  o << t.markdown();
  o << "\n## Disagreement groups\n\nSignature: backend, shape classes of A and B, the exact "
       "closest features (of A, then of B), the kind of error. Each group's first sample was "
       "shrunk while the backend's distance query still showed the signature; `reproduced` "
       "says whether `rbx distance` marks it on the scene.\n\n";
  o << groups_table(s);
  return o.str();
}

std::string markdown_toi(const ExploreSummary& s) {
  std::ostringstream o;
  o << "# rbx explore: " << s.count << " random moving pairs, seed " << s.seed << "\n\n"
    << "Every sample is a separated pair of the distance kind's (hulls cut to 64 points) moving "
       "over an interval of 1 s: head-on (the touch at a drawn fraction of the interval), "
       "oblique (with a sideways drift), spinning (each body turning up to 2 rad), hair-miss "
       "(ending 1e-9 to 1e-4 of the smaller size short of a touch) or graze (sideways only). "
       "Each backend's time-of-impact query, and its variants', is checked against the exact "
       "oracle as `rbx toi` checks it. A disagreement is a status error, a missed touch "
       "(misses), a touch where there is none (false_contact), or a first touch more than 1e-6 "
       "of the interval before or after the oracle's (early, late; docs/time_of_impact.md).\n\n";
  o << "## Backends\n\n";
  Table t(
      {"backend", "samples", "disagreements", "rate", "time err p50/p90/p99", "worst time err"});
  for (const ExploreBackendSummary& b : s.backends)
    t.add(cells(counts(b), {three(b, "time_err"), fmt_num(b.error("time_err").max, 2)}));
  o << t.markdown();
  o << "\n## Disagreement groups\n\nSignature: backend, shape classes of A and B, whether the "
       "oracle has a touch (touch, no_touch), the kind of error. Each group's first pair was "
       "shrunk, the motion as drawn, while the row still showed the signature; `reproduced` "
       "says whether `rbx toi` marks it on the scene.\n\n";
  o << groups_table(s);
  return o.str();
}

}  // namespace

std::string explore_markdown(const ExploreSummary& s, bool have_figure) {
  if (s.kind == "distance") return markdown_distance(s);
  if (s.kind == "toi") return markdown_toi(s);
  if (s.kind == "tunnel") return markdown_tunnel(s);
  if (s.kind == "impact") return markdown_impact(s);
  if (s.kind == "landing") return markdown_landing(s);
  if (s.kind == "slide") return markdown_slide(s);
  std::ostringstream o;
  o << "# rbx explore: " << s.count << " random contact pairs, seed " << s.seed << "\n\n"
    << "Every sample is a random convex pair (boxes, hulls of 4 to 2,000 points, slivers; size "
       "ratios up to 1e3) at a pose biased toward hard cases, checked against the exact oracle. A "
       "disagreement is a status error, a touching mismatch beyond 1e-9 of the smaller body, a "
       "normal more than 1 degree off (ties counted as right), a depth or any of its points more "
       "than 1 % of the smaller body off, or points that fall short of the exact contact patch by "
       "more "
       "than 1 % of it (*coverage*: the largest distance from a corner of the patch to the hull "
       "of the points, across the normal, relative to the smaller body; 0 when they span it, "
       "docs/contact_manifold.md). A one-point answer to a face contact is such a miss: it "
       "cannot hold a body from tipping. The coverage misses are also counted apart, whatever "
       "else the answer misses.\n\n";
  o << "## Backends\n\n";
  Table t({"backend", "samples", "disagreements", "rate", "normal p50/p90/p99 (deg)",
           "depth p50/p90/p99 (rel)", "worst point p99 (rel)", "coverage p50/p90/p99 (rel)",
           "coverage misses (> 1 %)"});
  for (const ExploreBackendSummary& b : s.backends)
    t.add(cells(counts(b), {three(b, "normal_err_deg"), three(b, "depth_err_rel"),
                            fmt_num(b.error("point_err_rel").p99, 2), three(b, "coverage_err_rel"),
                            std::to_string(b.coverage_misses.value_or(0))}));
  o << t.markdown();
  if (have_figure) o << "\n![error distributions per backend](explore_errors.png)\n";
  o << "\n## Disagreement groups\n\nSignature: backend, shape classes of A and B, the exact "
       "oracle's axis (face_a, face_b, edge_edge, or separated), the kind of error. Each group's "
       "first sample was shrunk to the scene named; `reproduced` says whether `rbx compare` shows "
       "the same disagreement on it.\n\n";
  o << groups_table(s);
  return o.str();
}

bool draw_explore_figure(const std::string& dir) {
  return run_figure_script("explore_plots.py", {dir}, (fs::path(dir) / "figures.log").string()) ==
         0;
}

}  // namespace rbx
