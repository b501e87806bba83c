#include "comparisons/eval/contact_eval.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"
#include "comparisons/eval/patch_cover.h"
#include "engine/detect.h"
#include "engine/format.h"
#include "reference/isolate.h"

namespace rbx {

ContactRun run_contact(const Backend& b, const RigidBody& a, const RigidBody& bb) {
  ContactRun run;
  if (!b.contact) {
    run.result = {Status::Unsupported, b.name + " has no contact query (dynamics only)", {}};
    return run;
  }
  auto answer = [&] {
    TimedContact t;
    Stopwatch clock;
    try {
      t.result = b.contact(a, bb);
    } catch (const std::exception& e) {
      t.result = {Status::Error, e.what(), {}};
    }
    t.runtime_s = clock.seconds();
    return t;
  };
  // A library's query runs isolated, under its deadline (reference/isolate.h); ours in process.
  const TimedContact t =
      b.library ? isolated_contact(b.name, CallDeadlines{}.contact_s, answer) : answer();
  run.result = t.result;
  run.timing.cold_s = t.runtime_s;
  return run;
}

bool timeable(const ContactRun& run) {
  return run.result.status == Status::Ok || run.result.status == Status::Touching;
}

void time_contacts(const std::vector<const Backend*>& backends, std::vector<ContactRun*> runs,
                   const RigidBody& a, const RigidBody& b, const TimingPlan& plan) {
  std::vector<TimedSubject> subjects;
  std::vector<Timing*> timed;
  for (size_t i = 0; i < backends.size() && i < runs.size(); ++i) {
    const Backend& be = *backends[i];
    if (runs[i]->cached || !timeable(*runs[i]) || !be.contact) continue;
    subjects.push_back(
        {be.name, be.library, [&be, &a, &b] { be.contact(a, b); }, CallDeadlines{}.contact_s});
    timed.push_back(&runs[i]->timing);
  }
  time_into(subjects, timed, plan);
}

TimedDynamics run_dynamics_isolated(const Backend& b, const WorldDefinition& scene,
                                    const DynamicsOptions& opt) {
  auto run = [&] {
    TimedDynamics t;
    Stopwatch clock;
    try {
      t.result = b.dynamics(scene, opt);
    } catch (const std::exception& e) {
      t.result = DynamicsResult{};
      t.result.status = Status::Error;
      t.result.message = e.what();
    }
    t.runtime_s = clock.seconds();
    return t;
  };
  return b.library ? isolated_dynamics(b.name, CallDeadlines{}.dynamics_s, run) : run();
}

DynamicsFn isolated_dynamics_fn(const Backend& b) {
  return [&b](const WorldDefinition& scene, const DynamicsOptions& opt) {
    return run_dynamics_isolated(b, scene, opt).result;
  };
}

const ContactPoint* deepest(const ContactResult& r) {
  const ContactPoint* best = nullptr;
  for (const ContactPoint& c : r.contacts)
    if (!best || c.depth > best->depth) best = &c;
  return best;
}

bool ties_true_depth(const RigidBody& a, const RigidBody& b, const Vec3& normal, double true_depth,
                     double size) {
  if (!normal.allFinite() || !(normal.norm() > 0.5)) return false;
  const double along = overlap_along(*a.shape, a.pose(), *b.shape, b.pose(), normal.normalized());
  return std::abs(along - true_depth) <= 1e-12 * size;
}

double angle_deg(const Vec3& u, const Vec3& v) {
  const double c = u.normalized().dot(v.normalized());
  // atan2 of |u x v| and u.v is accurate near 0 and 180 degrees, where acos is not.
  const double s = u.normalized().cross(v.normalized()).norm();
  return std::atan2(s, c) * 180.0 / M_PI;
}

// Violations of [expect.contact] by one subject's answer: touching, then (where it touches)
// the normal and the depth, each within the scene's tolerance.
void expect_contact_failures(const std::string& who, const ExpectContact& ex, bool touch,
                             const Vec3& normal, double depth, double tol,
                             std::vector<std::string>& failures) {
  if (ex.touching && touch != *ex.touching)
    failures.push_back(who + ": touching is " + (touch ? "true" : "false"));
  if (!touch) {
    if (!ex.touching && (ex.normal || ex.depth))
      failures.push_back(who + ": no contact, where [expect.contact] gives one");
    return;
  }
  const Vec3 want = ex.normal ? ex.normal->normalized() : Vec3::Zero();
  const double off = ex.either_sign ? std::min((normal - want).norm(), (normal + want).norm())
                                    : (normal - want).norm();
  if (ex.normal && off > tol)
    failures.push_back(who + ": contact normal " + fmt_vec(normal, 8) + ", expected " +
                       fmt_vec(ex.normal->normalized(), 8));
  if (ex.depth && std::abs(depth - *ex.depth) > tol)
    failures.push_back(who + ": contact depth " + fmt_num(depth, 10) + ", expected " +
                       fmt_num(*ex.depth, 10));
}

void expect_patch_failures(const std::string& who, const std::vector<Vec3>& patch,
                           const std::vector<Vec3>& points, const Vec3& normal, double tol,
                           std::vector<std::string>& failures) {
  if (patch.empty() || points.empty()) return;
  double short_by = 0.0, off_by = 0.0;
  for (const Vec3& corner : patch)
    short_by = std::max(short_by, distance_to_hull_across(corner, points, normal));
  for (const Vec3& p : points) off_by = std::max(off_by, distance_to_hull_across(p, patch, normal));
  if (short_by > tol)
    failures.push_back(who + ": " + std::to_string(points.size()) +
                       (points.size() == 1 ? " contact point falls" : " contact points fall") +
                       " short of the [expect.contact] patch by " + fmt_num(short_by, 3) + " m");
  if (off_by > tol)
    failures.push_back(who + ": a contact point lies " + fmt_num(off_by, 3) +
                       " m off the [expect.contact] patch");
}

Vec3 centres_direction(const RigidBody& a, const RigidBody& b) {
  const Vec3 d = a.position - b.position;
  return d.norm() > 0 ? Vec3(d.normalized()) : Vec3::Zero();
}

}  // namespace rbx
