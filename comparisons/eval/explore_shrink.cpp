// Shrinking a contact sample of `rbx explore` to the simplest pose that still shows its
// disagreement, and checking that a shrunk scene reproduces it through the harness
// (comparisons/eval/explore.h).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/scene/mesh_io.h"
#include "comparisons/scene/scene_file.h"
#include "engine/body.h"
#include "engine/bounding.h"
#include "engine/format.h"
#include "reference/exact.h"

namespace rbx {

using namespace explore_detail;

namespace explore_detail {

// Angle (rad, in [0, pi]) of the rotation taking orientation `from` to `to`; NaN when either
// is not finite.
double rotation_angle(const Quat& from, const Quat& to) {
  const Quat d = to.normalized() * from.normalized().conjugate();
  return 2.0 * std::atan2(d.vec().norm(), std::abs(d.w()));
}

// Euler angles (degrees, R = Rz Ry Rx as the scene format) of a rotation.
Vec3 euler_deg(const Quat& q) {
  const Vec3 zyx = q.toRotationMatrix().eulerAngles(2, 1, 0);
  return Vec3(zyx[2], zyx[1], zyx[0]) * (180.0 / M_PI);
}

// x to the nearest multiple of grid, as the decimal number a reader would write (3 * 0.1 is
// 0.30000000000000004; its 12-digit text reads back as 0.3).
double round_to(double x, double grid) {
  NumberFormat f;
  f.digits = 12;
  f.signed_zero = true;
  return std::strtod(format_number(std::round(x / grid) * grid, f).c_str(), nullptr);
}

// Each coordinate to the nearest multiple of grid (as above).
Vec3 round_to(const Vec3& v, double grid) {
  return Vec3(round_to(v.x(), grid), round_to(v.y(), grid), round_to(v.z(), grid));
}

int point_count(const ContactSample& s) {
  auto n = [](const ExploreBody& e) {
    return e.shape_class == "box" ? 8 : static_cast<int>(e.points.size());
  };
  return n(s.a) + n(s.b);
}

}  // namespace explore_detail

ShrinkResult shrink(const ContactSample& start, const std::string& backend, const std::string& sig,
                    int max_evaluations) {
  const std::vector<std::string> names = {backend};
  // A candidate shows the disagreement when its scene text, through the harness, does.
  return shrink_with(
      start,
      [&](const ContactSample& c, SampleOutcome* out) {
        return shows_signature(evaluate_scene_text(sample_scene_text(c), names, c.pose_class,
                                                   c.a.shape_class + "-" + c.b.shape_class),
                               sig, out);
      },
      max_evaluations);
}

ShrinkResult shrink_with(const ContactSample& start, const ShowsDisagreement& shows,
                         int max_evaluations) {
  ShrinkResult r;
  r.sample = start;
  r.vertices_before = point_count(start);
  auto keeps = [&](const ContactSample& c, SampleOutcome* out = nullptr) {
    if (r.evaluations >= max_evaluations) return false;
    ++r.evaluations;
    try {
      return shows(c, out);
    } catch (const std::exception&) {
      // A candidate the loader rejects (a flat hull, say) is simply not simpler.
    }
    return false;
  };
  auto accept = [&](const ContactSample& c) {
    if (!keeps(c)) return false;
    r.sample = c;
    ++r.steps_accepted;
    return true;
  };

  // 1. Fewer points: only the hull's own vertices, then drop chunks of points (halves first).
  for (ExploreBody ContactSample::*body : {&ContactSample::a, &ContactSample::b}) {
    if ((r.sample.*body).shape_class == "box") continue;
    ContactSample c = r.sample;
    try {
      (c.*body).points = convex_hull((c.*body).points).vertices();
      if ((c.*body).points.size() < (r.sample.*body).points.size()) accept(c);
    } catch (const std::exception&) {
    }
    for (size_t chunk = (r.sample.*body).points.size() / 2; chunk >= 1; chunk /= 2) {
      for (size_t at = 0;
           at < (r.sample.*body).points.size() && (r.sample.*body).points.size() > 4;) {
        ContactSample d = r.sample;
        auto& p = (d.*body).points;
        const size_t end = std::min(at + chunk, p.size());
        if (p.size() - (end - at) < 4) break;
        p.erase(p.begin() + at, p.begin() + end);
        if (!accept(d)) at += chunk;
      }
      if (r.evaluations >= max_evaluations) break;
    }
  }
  // 2. A at the origin.
  {
    ContactSample c = r.sample;
    c.b.position -= c.a.position;
    c.a.position = Vec3::Zero();
    accept(c);
  }
  // 3. Rotations toward axis-aligned: none, then Euler angles rounded, coarsest grid first.
  const double grids_deg[] = {90, 45, 15, 5, 1, 0.1, 0.01, 0.001};
  for (ExploreBody ContactSample::*body : {&ContactSample::a, &ContactSample::b}) {
    ContactSample c = r.sample;
    (c.*body).use_degrees = true;
    (c.*body).rotation_deg = Vec3::Zero();
    if (accept(c)) continue;
    const Vec3 deg = euler_deg(build_orientation(r.sample.*body));
    for (double g : grids_deg) {
      ContactSample d = r.sample;
      (d.*body).use_degrees = true;
      (d.*body).rotation_deg = round_to(deg, g);
      if (accept(d)) break;
    }
  }
  // 4. Rounder positions, sizes and points, on grids relative to the smaller body's extent.
  const double small =
      std::min(shape_size(*build_shape(r.sample.a)), shape_size(*build_shape(r.sample.b)));
  const double unit = std::pow(10.0, std::floor(std::log10(small)));
  const double grids[] = {1, 0.5, 0.1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6};
  for (ExploreBody ContactSample::*body : {&ContactSample::a, &ContactSample::b}) {
    for (double g : grids) {
      ContactSample d = r.sample;
      (d.*body).position = round_to((d.*body).position, g * unit);
      if ((d.*body).position == (r.sample.*body).position || accept(d)) break;
    }
    for (double g : grids) {
      ContactSample d = r.sample;
      ExploreBody& e = d.*body;
      if (e.shape_class == "box") {
        e.box_size = round_to(e.box_size, g * unit);
        if (e.box_size.minCoeff() <= 0) continue;
      } else {
        for (Vec3& p : e.points) p = round_to(p, g * unit);
      }
      if (accept(d)) break;
    }
  }
  r.vertices_after = point_count(r.sample);
  if (!keeps(r.sample, &r.outcome)) {
    // The budget ran out before the final check: evaluate once more regardless of the budget.
    ++max_evaluations;
    keeps(r.sample, &r.outcome);
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// Reproduction through the harness

namespace {

// Slide and landing kinds' rest_time and lift_off: the harness checks final states, not when the
// box came to rest or how high it rose on the way; the written scene's own run (every step
// sampled) against its closed form, read from the scene. What was measured goes to `d`.
bool own_run_reproduces(const Scene& scene, const std::vector<RigidBody>& bodies,
                        const BackendOutcome& b, std::ostringstream& d) {
  const Backend* be = find_backend(b.backend);
  const DynamicsResult run =
      be ? run_dynamics_isolated(*be, scene, DynamicsOptions{0.0, 1}).result : DynamicsResult{};
  const Vec3 n = bodies[1].orientation * Vec3::UnitZ();
  const bool ran = run.status == Status::Ok;
  if (b.error == "lift_off") {
    const Vec3 rest =
        scene.expect && !scene.expect->bodies.empty() && scene.expect->bodies.front().position
            ? *scene.expect->bodies.front().position
            : bodies[0].position;
    const double rise = ran ? largest_rise(run.samples, bodies[0].position, rest, n) : -1.0;
    d << "rose " << rise << " m off its surface (the scene's own run, every step)";
    if (rise > kSlideLiftMark) return true;
    // A smaller rise names a slide's late rest that the box's normal momentum just before it
    // stopped accounts for (a slide's box starts on its surface; a landing's above it).
    const bool slide = (bodies[0].position - rest).dot(n) <= 0.1 * kSlideLiftMark;
    const double closed_form = ran && slide ? slide_rest_time(scene) : 0.0;
    if (!(closed_form > 0.0)) return false;
    const Vec3 v = bodies[0].velocity - bodies[0].velocity.dot(n) * n;
    const double measured = measured_rest_time(run.samples, n, scene.sim.duration);
    d << ", its time to rest off by " << measured - closed_form << " s";
    return std::abs(measured - closed_form) > kSlideRestTimeMark &&
           hop_accounts_for_rest(run.samples, n, measured, closed_form, scene.sim.friction,
                                 v.norm() / closed_form, rise);
  }
  const double off = ran ? std::abs(measured_rest_time(run.samples, n, scene.sim.duration) -
                                    slide_rest_time(scene))
                         : -1.0;
  d << "time to rest off by " << off << " s (the scene's own run, every step)";
  return off > kSlideRestTimeMark;
}

}  // namespace

bool harness_reproduces(const std::string& scene_text, const std::string& path,
                        const BackendOutcome& b, std::string* detail) {
  const Scene scene = parse_scene(scene_text, path);
  HarnessOptions hopt;
  hopt.backends = b.backend;
  hopt.studies = false;
  hopt.timing_budget_s = 0.0;  // one query each: no timing repeats
  const SceneEvaluation ev = evaluate_scene(scene, hopt);
  const std::vector<RigidBody> bodies = make_bodies(scene);
  const double size = std::min(shape_size(*bodies[0].shape), shape_size(*bodies[1].shape));
  auto metric = [&](const std::string& name) -> double {
    for (const Metric& m : ev.metrics)
      if (m.backend == b.backend && m.name == name) return m.value;
    return -1.0;
  };
  auto said = [&](const std::string& what) {
    for (const std::string& s : ev.disagreements)
      if (s.rfind(b.backend + " on ", 0) == 0 && s.find(what) != std::string::npos) return true;
    return false;
  };
  const std::string status = ev.json["backends"].contains(b.backend)
                                 ? ev.json["backends"][b.backend]["status"].get<std::string>()
                                 : "missing";
  bool ok = false;
  std::ostringstream d;
  if (b.error == "error" || b.error == "timeout") {
    ok = status == b.error;
    d << "status " << status;
  } else if (b.error == "misses") {
    ok = said("misses a contact");
    d << (ok ? "misses a contact" : "no missed contact");
  } else if (b.error == "no_normal") {
    ok = said("touching with no normal on a pair");
    d << (ok ? "touching with no normal on a penetrating pair" : "no touching answer");
  } else if (b.error == "false_contact") {
    ok = said("reports a contact where there is none");
    d << (ok ? "reports a contact where there is none" : "no false contact");
  } else if (b.error == "normal") {
    ok = metric("normal_err_deg") > kMarkAngleDeg;
    d << "normal_err_deg " << metric("normal_err_deg");
  } else if (b.error == "depth") {
    ok = metric("depth_err") > kMarkDepthRel * size;
    d << "depth_err " << metric("depth_err") << " m (size " << size << " m)";
  } else if (b.error == "point") {
    ok = metric("worst_point_err_rel") > kMarkDepthRel;
    d << "worst_point_err_rel " << metric("worst_point_err_rel");
  } else if (b.error == "coverage") {
    ok = metric("coverage_err_rel") > kMarkDepthRel;
    d << "coverage_err_rel " << metric("coverage_err_rel");
  } else if (b.error == "tunnel" && status == "ok") {
    // Tunnel kind: the harness's final position of the projectile against the wall's near face
    // (the second body's top face).
    const Json& p = ev.json["backends"][b.backend]["bodies"][bodies[0].name]["final"]["position"];
    const Vec3 n = bodies[1].orientation * Vec3::UnitZ();
    const Vec3 face = bodies[1].position + 0.5 * scene.bodies[1].box_size.z() * n;
    const double beyond =
        -n.dot(Vec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>()) - face);
    ok = beyond > 0.0;
    d << "final centre " << beyond << " m past the wall's near face";
  } else if (b.error == "impulse" || b.error == "spin" || b.error == "missed" ||
             b.error == "velocity") {
    // Impact and tunnel kinds: the harness's velocity error against the scene's [expect] closed
    // form.
    ok = metric("velocity_err_ke") > kMarkVelocityErr;
    d << "velocity_err_ke " << metric("velocity_err_ke");
  } else if ((b.error == "rest_time" || b.error == "lift_off") && status == "ok") {
    ok = own_run_reproduces(scene, bodies, b, d);
  } else if ((b.error == "position" || b.error == "turn" || b.error == "late_landing" ||
              b.error == "deep_contact" || b.error == "cone_excess") &&
             status == "ok") {
    // Landing and slide kinds: the harness's final state of the first body against the scene's
    // [expect] position (distance along the surface, the second body's top) and against its own
    // start orientation (turn).
    const Json& fin = ev.json["backends"][b.backend]["bodies"][bodies[0].name]["final"];
    const Json& p = fin["position"];
    const Json& q = fin["orientation"];
    const Vec3 want =
        scene.expect && !scene.expect->bodies.empty() && scene.expect->bodies.front().position
            ? *scene.expect->bodies.front().position
            : Vec3::Zero();
    const Vec3 n = bodies[1].orientation * Vec3::UnitZ();
    const Vec3 off = Vec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>()) - want;
    const double position_err = (off - off.dot(n) * n).norm();
    const double turn = rotation_angle(
        bodies[0].orientation,
        Quat(q[0].get<double>(), q[1].get<double>(), q[2].get<double>(), q[3].get<double>()));
    ok = b.error == "turn" ? !(turn <= kLandingTurnMark) : !(position_err <= kLandingPositionMark);
    if (b.error == "deep_contact" || b.error == "cone_excess")
      ok = !(turn <= kLandingTurnMark) || !(position_err <= kLandingPositionMark);
    // late_landing is such a position error, its size matched by explore to a late landing.
    d << "final position off by " << position_err << " m, turned by " << turn << " rad";
  } else if (b.error == "position" || b.error == "turn" || b.error == "rest_time" ||
             b.error == "tunnel" || b.error == "late_landing" || b.error == "deep_contact" ||
             b.error == "lift_off" || b.error == "cone_excess") {
    d << "status " << status;
  }
  if (detail) *detail = d.str();
  return ok;
}

}  // namespace rbx
