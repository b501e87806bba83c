#include "comparisons/eval/toi_query.h"

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

ToiRow answer_of(const ToiSubject& s, const RigidBody& a, const RigidBody& b, double dt) {
  ToiRow row;
  row.backend = s.name;
  row.result = run_toi(s, a, b, dt, &row.timing.cold_s);
  return row;
}

// Times every row that answered, interleaved as the contact queries are (docs/bench.md).
void time_rows(std::vector<ToiRow>& rows, const std::vector<ToiSubject>& subjects,
               const RigidBody& a, const RigidBody& b, double dt, double budget_s) {
  if (budget_s <= 0) return;
  std::vector<TimedSubject> timed_subjects;
  std::vector<Timing*> timed;
  for (size_t i = 0; i < rows.size(); ++i) {
    const ToiSubject& s = subjects[i];
    if (!s.fn || rows[i].result.status != Status::Ok) continue;
    timed_subjects.push_back(
        {s.name, s.library, [&s, &a, &b, dt] { s.fn(a, b, dt); }, CallDeadlines{}.contact_s});
    timed.push_back(&rows[i].timing);
  }
  TimingPlan plan;
  plan.min_time_s = budget_s;
  time_into(timed_subjects, timed, plan);
}

Json result_json(const ToiResult& r) {
  Json j = {{"status", to_string(r.status)}, {"message", r.message}};
  if (r.status != Status::Ok) return j;
  j["hit"] = r.hit;
  if (!r.hit) return j;
  j["fraction"] = r.fraction;
  if (r.located) {
    j["point"] = to_json(r.point);
    j["normal"] = to_json(r.normal);
  }
  return j;
}

}  // namespace

std::vector<ToiSubject> toi_subjects(const std::vector<std::string>& names) {
  std::vector<ToiSubject> out;
  for (const std::string& name : names) {
    const Backend* be = find_backend(name);
    out.push_back({name, be ? be->toi : nullptr, be ? be->library : false});
    // A variant with a contact query of its own is its backend set up otherwise (shapes built
    // once and kept): the same answers, timed apart by rbx bench, not a row here.
    for (const QueryVariant& v : query_variants())
      if (v.backend == name && v.toi && !v.contact)
        out.push_back({name + "/" + v.variant, v.toi, true});
  }
  return out;
}

ToiResult run_toi(const ToiSubject& s, const RigidBody& a, const RigidBody& b, double dt,
                  double* cold_s) {
  if (!s.fn) {
    ToiResult r;
    r.status = Status::Unsupported;
    r.message = s.name + " has no time-of-impact query";
    if (cold_s) *cold_s = 0;
    return r;
  }
  auto call = [&] {
    TimedToi t;
    Stopwatch clock;
    try {
      t.result = s.fn(a, b, dt);
    } catch (const std::exception& e) {
      t.result = ToiResult{};
      t.result.status = Status::Error;
      t.result.message = e.what();
    }
    t.runtime_s = clock.seconds();
    return t;
  };
  const TimedToi t = s.library ? isolated_toi(s.name, CallDeadlines{}.contact_s, call) : call();
  if (cold_s) *cold_s = t.runtime_s;
  return t.result;
}

namespace {

// The pair's exact separation at `fraction` of the interval: the distance where apart, minus the
// deepest exact depth where overlapping; NaN where the motion has no pose there.
double separation_at(const RigidBody& a, const RigidBody& b, double dt, double fraction) {
  const std::optional<RigidBody> at_a = body_at_end(a, fraction * dt),
                                 at_b = body_at_end(b, fraction * dt);
  if (!at_a || !at_b) return std::nan("");
  const ExactDistance e = exact_distance(*a.shape, at_a->pose(), *b.shape, at_b->pose());
  if (!e.overlapping) return e.distance;
  double depth = 0;
  for (const ContactPoint& c : exact_contact(*at_a, *at_b).contacts)
    depth = std::max(depth, c.depth);
  return -depth;
}

// Whether the pair at `fraction` of the interval is within kToiTouchBand of touching (exactly,
// by the oracle): apart by at most the band, or overlapping by at most it.
bool touching_at(const RigidBody& a, const RigidBody& b, double dt, double fraction) {
  const double band = kToiTouchBand * (bounding_sphere(a).radius + bounding_sphere(b).radius);
  return std::abs(separation_at(a, b, dt, fraction)) <= band;  // false for NaN
}

// Whether a touch the oracle finds at `fraction` is a hair-deep pass: at 17 instants from it to
// the interval's end the pair is apart, or overlapping by no more than kToiTouchBand of its
// size (a touch decided at the nanometre, as when a drift carries two nearly touching edges
// past each other).
bool hair_deep_pass(const RigidBody& a, const RigidBody& b, double dt, double fraction) {
  for (int k = 0; k <= 16; ++k) {
    const double t = fraction + (1.0 - fraction) * k / 16.0;
    if (touching_at(a, b, dt, t)) continue;
    const std::optional<RigidBody> at_a = body_at_end(a, t * dt), at_b = body_at_end(b, t * dt);
    if (!at_a || !at_b) return false;
    if (exact_distance(*a.shape, at_a->pose(), *b.shape, at_b->pose()).overlapping) return false;
  }
  return true;
}

}  // namespace

ToiVerdict judge_toi(const ToiResult& answer, const ToiResult& truth, const RigidBody& a,
                     const RigidBody& b, double dt) {
  ToiVerdict v;
  if (answer.status != Status::Ok || truth.status != Status::Ok) return v;
  // A touch where the oracle has none, at an instant the pair is within the band of touching
  // (a hair's miss): the same pass, read at another tolerance.
  if (answer.hit && !truth.hit && touching_at(a, b, dt, answer.fraction)) return v;
  if (!answer.hit && truth.hit && hair_deep_pass(a, b, dt, truth.fraction)) return v;
  if (answer.hit != truth.hit) {
    v.mark = "disagrees";
    v.why = answer.hit ? "reports a touch at " + fmt_num(answer.fraction, 9) +
                             " of the interval; the pair does not touch within it"
                       : "misses the touch at " + fmt_num(truth.fraction, 9) + " of the interval";
    return v;
  }
  if (!truth.hit) return v;
  v.comparable = true;
  v.time_err = std::abs(answer.fraction - truth.fraction);
  const bool grazing = v.time_err > kToiDeviate && touching_at(a, b, dt, answer.fraction);
  if (!std::isfinite(v.time_err) || (v.time_err > kToiDisagree && !grazing)) {
    v.mark = "disagrees";
    if (const double s = separation_at(a, b, dt, answer.fraction); std::isfinite(s))
      v.separation_m = s;
  } else if (v.time_err > kToiDeviate && !grazing)
    v.mark = "deviates";
  if (!v.mark.empty())
    v.why = "touches at " + fmt_num(answer.fraction, 9) + " of the interval; exact " +
            fmt_num(truth.fraction, 9) + " (off by " + fmt_num(v.time_err, 3) + ")";
  const std::optional<RigidBody> at_a = body_at_end(a, truth.fraction * dt),
                                 at_b = body_at_end(b, truth.fraction * dt);
  if (answer.located && truth.located && at_a && at_b) {
    v.located = true;
    const double c = std::clamp(answer.normal.normalized().dot(truth.normal), -1.0, 1.0);
    v.normal_err_deg = std::acos(c) * 180.0 / M_PI;
    const double size = bounding_sphere(a).radius + bounding_sphere(b).radius;
    v.point_err_rel = std::max(exact_point_distance(*a.shape, at_a->pose(), answer.point),
                               exact_point_distance(*b.shape, at_b->pose(), answer.point)) /
                      size;
  }
  return v;
}

ToiComparison compare_tois(const Scene& scene, const std::vector<std::string>& names,
                           double interval, double budget_s) {
  ToiComparison c;
  c.scene = scene.name;
  c.file = scene.file;
  c.interval = interval;
  const std::vector<RigidBody> bodies = make_bodies(scene);
  const std::vector<ToiSubject> subjects = toi_subjects(names);
  const std::vector<ToiSubject> oracle = toi_subjects({"exact"});
  for (size_t i = 0; i < bodies.size(); ++i)
    for (size_t j = i + 1; j < bodies.size(); ++j) {
      const RigidBody &a = bodies[i], &b = bodies[j];
      if (a.is_static && b.is_static) continue;
      ToiPair p;
      p.a = a.name;
      p.b = b.name;
      p.truth = answer_of(oracle.at(0), a, b, interval).result;
      for (const ToiSubject& s : subjects) p.rows.push_back(answer_of(s, a, b, interval));
      time_rows(p.rows, subjects, a, b, interval, budget_s);
      for (ToiRow& r : p.rows) r.verdict = judge_toi(r.result, p.truth, a, b, interval);
      if (c.pairs.empty() && scene.expect && scene.expect->toi) {
        // The first pair's stated answer: the oracle's and each bound engine's against it.
        ToiResult stated;
        stated.hit = scene.expect->toi->touch;
        stated.fraction = scene.expect->toi->fraction;
        c.expect.stated = stated.hit
                              ? "a touch at " + fmt_num(stated.fraction, 10) + " of the interval"
                              : "no touch";
        // Held to the statement itself (judge_toi trusts a touching instant over its truth): a
        // touch against a stated miss, or the reverse, is a miss unless the pass from the touch
        // on is hair-deep (decided at the nanometre); a touch at another time, unless both
        // instants are within the touching band (a grazing touch).
        auto disagrees = [&](const ToiResult& r) {
          if (r.status != Status::Ok) return true;
          if (r.hit != stated.hit)
            return !hair_deep_pass(a, b, interval, r.hit ? r.fraction : stated.fraction);
          if (!r.hit) return false;
          return std::abs(r.fraction - stated.fraction) > kToiDisagree &&
                 !(touching_at(a, b, interval, r.fraction) &&
                   touching_at(a, b, interval, stated.fraction));
        };
        file_stated(c.expect, *scene.expect, "exact", disagrees(p.truth));
        for (const ToiRow& r : p.rows)
          if (bound_by(*scene.expect, r.backend))
            file_stated(c.expect, *scene.expect, r.backend, disagrees(r.result));
      }
      c.pairs.push_back(std::move(p));
    }
  return c;
}

Json toi_json(const ToiComparison& c) {
  Json j = {{"scene", c.scene}, {"file", c.file}, {"query", "toi"}, {"interval", c.interval}};
  j["pairs"] = Json::array();
  for (const ToiPair& p : c.pairs) {
    Json pj = {{"bodies", {p.a, p.b}}, {"exact", result_json(p.truth)}};
    pj["backends"] = Json::object();
    for (const ToiRow& r : p.rows) {
      Json rj = result_json(r.result);
      if (r.verdict.comparable) rj["time_err"] = r.verdict.time_err;
      if (r.verdict.comparable && r.verdict.mark == "disagrees")
        rj["separation_m"] = r.verdict.separation_m;
      if (r.verdict.located) {
        rj["normal_err_deg"] = r.verdict.normal_err_deg;
        rj["point_err_rel"] = r.verdict.point_err_rel;
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
