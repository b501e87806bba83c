#include "comparisons/eval/distance_query.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include "comparisons/eval/measures.h"
#include "engine/bounding.h"
#include "engine/format.h"
#include "reference/exact.h"
#include "reference/isolate.h"

namespace rbx {

namespace {

// One backend's answer, its first call timed alone.
DistanceRow answer_of(const Backend* be, const std::string& name, const RigidBody& a,
                      const RigidBody& b) {
  DistanceRow row;
  row.backend = name;
  if (!be) {
    row.result.status = Status::Unsupported;
    row.result.message = name + " has no distance query";
    return row;
  }
  row.result = run_distance(*be, a, b, &row.timing.cold_s);
  return row;
}

// Times every row that answered, interleaved as the contact queries are (docs/bench.md).
void time_rows(std::vector<DistanceRow>& rows, const RigidBody& a, const RigidBody& b,
               double budget_s) {
  if (budget_s <= 0) return;
  std::vector<TimedSubject> subjects;
  std::vector<Timing*> timed;
  for (DistanceRow& r : rows) {
    const Backend* be = find_backend(r.backend);
    if (!be || !be->distance || r.result.status != Status::Ok) continue;
    subjects.push_back(
        {be->name, be->library, [be, &a, &b] { be->distance(a, b); }, CallDeadlines{}.contact_s});
    timed.push_back(&r.timing);
  }
  TimingPlan plan;
  plan.min_time_s = budget_s;
  time_into(subjects, timed, plan);
}

// How far the pair's farthest vertex can be from the world origin (m): the magnitude of the
// coordinates every answer is computed in.
double extent(const RigidBody& a, const RigidBody& b) {
  const BoundingSphere sa = bounding_sphere(a), sb = bounding_sphere(b);
  return std::max(sa.center.norm() + sa.radius, sb.center.norm() + sb.radius);
}

Json result_json(const DistanceResult& r) {
  Json j = {{"status", to_string(r.status)}, {"message", r.message}};
  if (r.status != Status::Ok) return j;
  j["overlapping"] = r.overlapping;
  if (r.overlapping) return j;
  j["distance"] = r.distance;
  j["point_a"] = to_json(r.point_a);
  j["point_b"] = to_json(r.point_b);
  return j;
}

}  // namespace

DistanceResult run_distance(const Backend& be, const RigidBody& a, const RigidBody& b,
                            double* cold_s) {
  if (!be.distance) {
    DistanceResult r;
    r.status = Status::Unsupported;
    r.message = be.name + " has no distance query";
    return r;
  }
  auto call = [&] {
    TimedDistance t;
    Stopwatch clock;
    try {
      t.result = be.distance(a, b);
    } catch (const std::exception& e) {
      t.result = DistanceResult{};
      t.result.status = Status::Error;
      t.result.message = e.what();
    }
    t.runtime_s = clock.seconds();
    return t;
  };
  const TimedDistance t =
      be.library ? isolated_distance(be.name, CallDeadlines{}.contact_s, call) : call();
  if (cold_s) *cold_s = t.runtime_s;
  return t.result;
}

DistanceVerdict judge_distance(const DistanceResult& answer, const DistanceResult& truth,
                               const RigidBody& a, const RigidBody& b) {
  DistanceVerdict v;
  const double size = extent(a, b);
  v.scale = std::max(truth.distance, kDistanceFloorRel * size);
  if (answer.status != Status::Ok || truth.status != Status::Ok) return v;
  // Touching to round-off: "overlapping" and a zero distance are both right.
  const bool touching = !truth.overlapping && truth.distance <= kDistanceFloorRel * size;
  if (answer.overlapping != truth.overlapping) {
    if (touching) return v;
    v.mark = "disagrees";
    v.why = answer.overlapping
                ? "says the pair overlaps; it is " + fmt_num(truth.distance, 6) + " m apart"
                : "gives a distance (" + fmt_num(answer.distance, 6) + " m) to an overlapping pair";
    return v;
  }
  if (truth.overlapping) return v;
  v.comparable = true;
  v.distance_err = std::abs(answer.distance - truth.distance) / v.scale;
  const double off_a = exact_point_distance(*a.shape, a.pose(), answer.point_a);
  const double off_b = exact_point_distance(*b.shape, b.pose(), answer.point_b);
  const double gap = std::abs((answer.point_a - answer.point_b).norm() - truth.distance);
  v.witness_err = std::max({off_a, off_b, gap}) / v.scale;
  const double worst = std::max(v.distance_err, v.witness_err);
  if (!std::isfinite(worst) || worst > kDistanceDisagreeRel)
    v.mark = "disagrees";
  else if (worst > std::max(kDistanceDeviateRel, kDistanceRoundOffRel * size / v.scale))
    v.mark = "deviates";
  if (!v.mark.empty())
    v.why = "distance off by " + fmt_num(v.distance_err, 3) + ", witness points off by " +
            fmt_num(v.witness_err, 3) + " of the distance";
  return v;
}

DistanceComparison compare_distances(const Scene& scene, const std::vector<std::string>& names,
                                     double budget_s) {
  DistanceComparison c;
  c.scene = scene.name;
  c.file = scene.file;
  const std::vector<RigidBody> bodies = make_bodies(scene);
  for (size_t i = 0; i < bodies.size(); ++i)
    for (size_t j = i + 1; j < bodies.size(); ++j) {
      const RigidBody &a = bodies[i], &b = bodies[j];
      if (a.is_static && b.is_static) continue;
      DistancePair p;
      p.a = a.name;
      p.b = b.name;
      p.truth = answer_of(find_backend("exact"), "exact", a, b).result;
      for (const std::string& name : names)
        p.rows.push_back(answer_of(find_backend(name), name, a, b));
      time_rows(p.rows, a, b, budget_s);
      for (DistanceRow& r : p.rows) r.verdict = judge_distance(r.result, p.truth, a, b);
      if (c.pairs.empty() && scene.expect && scene.expect->distance) {
        // The first pair's stated answer: the oracle's and each bound engine's against it.
        DistanceResult stated;
        stated.overlapping = scene.expect->distance->overlapping;
        stated.distance = scene.expect->distance->distance;
        c.expect.stated = stated.overlapping ? "overlapping" : fmt_num(stated.distance, 10) + " m";
        auto disagrees = [&](const DistanceResult& r) {
          return judge_distance(r, stated, a, b).mark == "disagrees";
        };
        file_stated(c.expect, *scene.expect, "exact", disagrees(p.truth));
        for (const DistanceRow& r : p.rows)
          if (bound_by(*scene.expect, r.backend))
            file_stated(c.expect, *scene.expect, r.backend, disagrees(r.result));
      }
      c.pairs.push_back(std::move(p));
    }
  return c;
}

Json distance_json(const DistanceComparison& c) {
  Json j = {{"scene", c.scene}, {"file", c.file}, {"query", "distance"}};
  j["pairs"] = Json::array();
  for (const DistancePair& p : c.pairs) {
    Json pj = {{"bodies", {p.a, p.b}}, {"exact", result_json(p.truth)}};
    pj["backends"] = Json::object();
    for (const DistanceRow& r : p.rows) {
      Json rj = result_json(r.result);
      if (r.verdict.comparable) {
        rj["distance_err_rel"] = r.verdict.distance_err;
        rj["witness_err_rel"] = r.verdict.witness_err;
      }
      rj["mark"] = r.verdict.mark;
      if (!r.verdict.why.empty()) rj["why"] = r.verdict.why;
      put_timing(r.timing, rj);
      pj["backends"][r.backend] = rj;
    }
    j["pairs"].push_back(pj);
  }
  if (!c.expect.stated.empty()) j["expect"] = stated_json(c.expect);
  return j;
}

}  // namespace rbx
