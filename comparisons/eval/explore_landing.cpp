// The landing kind of `rbx explore`: a box falling flat onto a floor while it slides, with
// friction, drawn, realised as a scene with its closed form (the fall, the landing's Coulomb
// impulse, the slide to rest), judged and shrunk (comparisons/eval/explore.h).
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/measures.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/scene/scene_file.h"

namespace rbx {

using namespace explore_detail;

namespace {

// After the closed-form rest, the run goes on this long (s): a backend's rest is seen at rest.
constexpr double kLandingSettleTime = 0.1;

// The box and the floor of a landing as scene bodies (box first: A, then B as impact).
ExploreBody landing_box(const LandingSample& s) {
  ExploreBody e;
  e.shape_class = "box";
  e.box_size = s.size;
  e.position = s.start_position;
  e.use_degrees = true;
  e.rotation_deg = Vec3(0.0, 0.0, s.yaw_deg);
  return e;
}

// A floor slab 1 m thick, top at z = 0, whole metres wide, reaching at least 0.5 m past the
// box's whole path (from the origin to its rest).
ExploreBody landing_floor(const LandingSample& s, double travel) {
  ExploreBody e;
  e.shape_class = "box";
  const double reach = std::ceil(travel + 0.5 * std::hypot(s.size.x(), s.size.y()) + 0.5);
  e.box_size = Vec3(2.0 * reach, 2.0 * reach, 1.0);
  e.position = Vec3(0.0, 0.0, -0.5);
  return e;
}

// A position miss that a late landing accounts for, measured on the run's own steps: the floor
// first acted after the step of the touch (no time of impact); the landing's friction, summed
// over the steps it took to stop the fall, was Coulomb's at their summed normal impulse; and from
// the state after it the box slid to rest as Coulomb's slide does (v^2 / 2 mu g along its speed,
// within the slide's own discretisation, v dt / 2). Found a step late the box is deeper, and a
// library that then pushes back harder than m vn takes, with the same cone, more of what was left
// of the slide: the rest is then along the launch, past the late step's slide less the slide left
// after the landing (v_h'^2 / 2 mu g) and short of the late step's slide alone (`late`), each
// within `slack`.
bool late_landing_accounts(const std::vector<StateSample>& samples, const LandingSample& s,
                           const Vec3& off, const Vec3& launch, double late, double slack) {
  const double mu = s.friction, dt = s.dt;
  const double left = s.speed_after * s.speed_after / (2.0 * mu * kGravity);
  const double along = off.dot(launch);
  if (!(along >= late - left - slack && along <= late + slack &&
        (off - along * launch).norm() <= 1e-5))
    return false;
  // The first sample the floor acted on (its fall slower than free fall's, beyond round-off),
  // and the first whose fall it had stopped.
  size_t first = 0, landed = 0;
  for (size_t k = 1; k < samples.size() && landed == 0; ++k) {
    const double free_fall = -s.fall_speed - kGravity * samples[k].time;
    const double vz = samples[k].bodies[0].velocity.z();
    if (first == 0 && vz > free_fall + 1e-9 * s.fall_speed) first = k;
    if (first != 0 && vz >= -0.1 * s.fall_speed) landed = k;
  }
  const double touch_step_end = (s.steps_before + 1) * dt;
  if (landed == 0 || !(samples[first].time > touch_step_end + 1e-6 * dt)) return false;
  const Vec3 before = samples[first - 1].bodies[0].velocity;
  const Vec3 after = samples[landed].bodies[0].velocity;
  const Vec3 h_after(after.x(), after.y(), 0.0);
  // The landing's normal impulse per unit mass: the fall it stopped and its steps' gravity.
  const double normal =
      after.z() - before.z() + kGravity * (samples[landed].time - samples[first - 1].time);
  const double tangential = (Vec3(before.x(), before.y(), 0.0) - h_after).norm();
  const double v = h_after.norm();
  // Coulomb: a base still slipping after the landing (above the time to rest's 1 mm/s) had mu
  // times the normal impulse (to 1 %: a soft contact meets its cone to its solver's tolerance);
  // a stopped one at most that (to round-off). A landing with too little friction is not a
  // late one.
  const bool coulomb = v > 1e-3 ? std::abs(tangential - mu * normal) <= 1e-2 * mu * normal
                                : tangential <= mu * normal * (1.0 + 1e-9) + 1e-12;
  if (!coulomb) return false;
  const Vec3& p = samples[landed].bodies[0].position;
  Vec3 stop(p.x(), p.y(), 0.0);
  if (v > 0.0) stop += v / (2.0 * mu * kGravity) * h_after;  // v^2 / 2 mu g along h_after / v
  const Vec3 rest = s.expect_position + off;
  return (Vec3(rest.x(), rest.y(), 0.0) - stop).norm() <= 0.5 * v * dt + 1e-5;
}

}  // namespace

bool realize_landing(LandingSample& s) {
  s.text.clear();
  const double mu = s.friction, g = kGravity;
  const double footprint = std::min(s.size.x(), s.size.y());
  if (!(s.size.minCoeff() > 0 && s.mass > 0 && s.fall_speed > 0 && s.slide_speed >= 0 && mu > 0 &&
        s.dt > 0 && s.steps_before >= 1 && s.phase >= 0.02 && s.phase <= 0.98))
    return false;
  if (!(mu * s.size.z() <= kNoTipMargin * footprint)) return false;  // could tip
  // 1. Free fall to the first touch at t_c = (k + phase) dt: the base starts h0 above the floor.
  const double tc = (s.steps_before + s.phase) * s.dt;
  s.contact_time = tc;
  s.drop = s.fall_speed * tc + 0.5 * g * tc * tc;
  // 2. The landing (e = 0): the normal impulse stops the fall; the friction impulse is Coulomb's,
  //    mu J while the base slips through it, else what stops the slip.
  const double vn = s.fall_speed + g * tc;
  s.normal_impulse = s.mass * vn;
  s.slides = s.slide_speed > mu * vn;
  s.friction_impulse = s.slides ? mu * s.normal_impulse : s.mass * s.slide_speed;
  s.speed_after = s.slides ? s.slide_speed - mu * vn : 0.0;
  // 3. The slide: deceleration mu g to rest, then static friction holds.
  s.rest_time = tc + s.speed_after / (mu * g);
  const double before = s.slide_speed * tc;
  const double after = s.speed_after * s.speed_after / (2.0 * mu * g);
  s.duration = std::ceil((s.rest_time + kLandingSettleTime) / s.dt) * s.dt;
  const double heading = s.heading_deg * M_PI / 180.0;
  const Vec3 dir(std::cos(heading), std::sin(heading), 0.0);
  s.start_position = Vec3(0.0, 0.0, 0.5 * s.size.z() + s.drop);
  s.velocity = s.slide_speed * dir - Vec3(0.0, 0.0, s.fall_speed);
  s.expect_position = (before + after) * dir + Vec3(0.0, 0.0, 0.5 * s.size.z());

  std::ostringstream o;
  o << "description = \"rbx explore landing seed " << s.seed << " sample " << s.index << " ("
    << (s.slides ? "slides" : "sticks") << " after the landing, mu = " << num(mu) << ")\"\n";
  o << "checks = [\"impulse\"]\n\n[sim]\ndt = " << num(s.dt) << "\nduration = " << num(s.duration)
    << "\ngravity = " << vec(Vec3(0.0, 0.0, -g)) << "\nrestitution = 0.0\nfriction = " << num(mu)
    << "\n\n";
  o << dynamic_body_text(landing_box(s), "box", s.mass, s.velocity, false) << "\n"
    << dynamic_body_text(landing_floor(s, before + after), "floor", 1.0, Vec3::Zero(), true);
  o << "\n# Closed form (rbx explore, landing kind; g = " << num(g) << " m/s^2, m = " << num(s.mass)
    << " kg, mu = " << num(mu)
    << ").\n# Fall: the base starts h0 = vz t_c + g t_c^2 / 2 = " << num(s.drop)
    << " m above the floor, so it first\n# touches at t_c = (k + phase) dt = " << num(tc)
    << " s (k = " << s.steps_before << ", phase " << num(s.phase) << "), flat (no spin).\n"
    << "# Landing, e = 0: vn = vz + g t_c = " << num(vn)
    << " m/s stopped, J = m vn = " << num(s.normal_impulse)
    << " N s.\n# Friction impulse min(mu J, m |v_h|) = " << num(s.friction_impulse)
    << " N s against v_h (|v_h| = " << num(s.slide_speed) << " m/s, heading " << num(s.heading_deg)
    << " deg):\n# "
    << (s.slides ? "|v_h| > mu vn, the base slides on at |v_h'| = |v_h| - mu vn = "
                 : "|v_h| <= mu vn, the landing stops the slip: |v_h'| = ")
    << num(s.speed_after) << " m/s.\n# Slide: decelerating at mu g to rest at t = t_c + |v_h'| / "
    << "(mu g) = " << num(s.rest_time) << " s, over\n# |v_h'|^2 / (2 mu g) = " << num(after)
    << " m, after |v_h| t_c = " << num(before) << " m before the landing.\n"
    << "# No turn: friction's moment about the centre, mu N sz / 2, is balanced by the pressure\n"
    << "# shifting toward the front edge, possible while mu sz < min(sx, sy) (here "
    << num(mu * s.size.z()) << " < " << num(footprint) << ").\n"
    << "# At t = duration: at rest, centre " << vec(s.expect_position)
    << ", orientation unchanged.\n";
  o << box_at_rest_expect("|v_h'|", s.speed_after, s.dt, s.expect_position);
  s.text = o.str();
  return true;
}

LandingSample make_landing_sample(uint64_t seed, uint64_t index) {
  return first_realized<LandingSample>(
      seed, index, 10, "landing", [](SampleRng& r, LandingSample& s) {
        draw_box(r, s.friction, s.size, s.mass, s.yaw_deg, kNoTipMargin);
        // Slide speeds to 1.5 m/s (kLandingPositionMark says why), falls of 0.2 to 2 m/s.
        s.slide_speed = r.uniform(0.05, 1.5);
        s.heading_deg = r.uniform(0.0, 360.0);
        s.fall_speed = r.uniform(0.2, 2.0);
        s.dt = 1e-3;
        s.steps_before = r.integer(2, 5);
        s.phase = r.uniform(0.02, 0.98);
        return realize_landing(s);
      });
}

SampleOutcome evaluate_landing_sample(const LandingSample& s, const std::vector<std::string>& names,
                                      const std::vector<Backend>* table, const ResultCache* cache) {
  SampleOutcome out;
  out.index = s.index;
  out.pose_class = "landing";
  out.shapes = "box-floor";
  out.feature = s.slides ? "slides" : "sticks";
  out.touching = true;
  out.phase = s.phase;
  const Scene scene = parse_scene(s.text, "explore.toml");
  const std::vector<RigidBody> inputs = make_bodies(scene);
  const double e0 = 0.5 * inputs[0].mass * inputs[0].velocity.squaredNorm();
  // At rest at the end: the KE norm falls back on the initial kinetic energy.
  const std::vector<std::optional<RefState>> ref = {RefState{Vec3::Zero(), Vec3::Zero()},
                                                    std::nullopt};
  // The sign of a landing resolved only at the step after the touch (no time of impact): the base
  // keeps its speed before the landing for the rest of that step, (1 - phase) dt, and rests
  // (|v_h| - |v_h'|) (1 - phase) dt further along its launch; the slide after the landing adds at
  // most its own discretisation, |v_h'| dt / 2. Matched within that and 1e-5 m (1 % of the
  // mark), along the launch and not across it.
  const double heading = s.heading_deg * M_PI / 180.0;
  const Vec3 launch(std::cos(heading), std::sin(heading), 0.0);
  const double late = (s.slide_speed - s.speed_after) * (1.0 - s.phase) * s.dt;
  const double slack = 0.5 * s.speed_after * s.dt + 1e-5;
  // Every step sampled: the time to rest is read from the samples.
  run_dynamics_subjects(
      scene, names, DynamicsOptions{0.0, 1}, table, cache, out,
      [&](BackendOutcome& o, const DynamicsResult& run) {
        const BodyFinal& f = run.finals[0];
        const Vec3 off(f.position.x() - s.expect_position.x(),
                       f.position.y() - s.expect_position.y(), 0.0);
        o.position_err_m = off.norm();
        o.turn_rad = rotation_angle(inputs[0].orientation, f.orientation);
        o.velocity_err_ke = ke_norm_error(inputs, run.finals, ref, e0);
        o.rest_time_err_s =
            std::abs(measured_rest_time(run.samples, Vec3::UnitZ(), s.duration) - s.rest_time);
        if (!(o.turn_rad <= kLandingTurnMark))
          o.error = "turn";
        else if (!(o.position_err_m <= kLandingPositionMark))
          o.error = (std::abs(off.dot(launch) - late) <= slack &&
                     (off - off.dot(launch) * launch).norm() <= 1e-5) ||
                            late_landing_accounts(run.samples, s, off, launch, late, slack)
                        ? "late_landing"
                        : "position";
        name_deep_contact(o, run, s.size.minCoeff());
        o.rise_m = largest_rise(run.samples, s.start_position, s.expect_position, Vec3::UnitZ());
        if ((o.error == "turn" || o.error == "position") && o.rise_m > kSlideLiftMark)
          o.error = "lift_off";
        name_cone_excess(o, run, off, launch, s.speed_after > 0.0 ? s.friction * kGravity : 0.0,
                         inputs[0].orientation, f.orientation, Vec3::UnitZ());
      });
  return out;
}

LandingShrinkResult shrink_landing(const LandingSample& start, const std::string& backend,
                                   const std::string& sig, int max_evaluations) {
  DesignShrinker<LandingSample> k(
      start, backend, sig, max_evaluations, realize_landing,
      [](const LandingSample& s, const std::vector<std::string>& names) {
        return evaluate_landing_sample(s, names);
      });

  // 1. Unit mass, no yaw, a slide along x (else an axis), the first touch two steps ahead.
  k.round_down(&LandingSample::mass, 1.0, {});
  k.round_down(&LandingSample::yaw_deg, 0.0, {90, 45, 15, 5, 1});
  k.round_down(&LandingSample::heading_deg, 0.0, {90, 45, 15, 5, 1});
  {
    LandingSample c = k.sample;
    c.steps_before = 2;
    if (c.steps_before != k.sample.steps_before) k.accept(c);
  }
  // 2. Rounder mu, sizes, speeds and phase.
  k.round_down(&LandingSample::friction, 0.5, {0.1, 0.05, 0.01});
  k.round_size();
  k.round_down(&LandingSample::slide_speed, 1.0, {0.5, 0.1, 0.01});
  k.round_down(&LandingSample::fall_speed, 1.0, {0.5, 0.1, 0.01});
  k.round_down(&LandingSample::phase, 0.5, {0.1, 0.01});
  return k.template result<LandingShrinkResult>();
}

}  // namespace rbx
