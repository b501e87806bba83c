// The slide kind of `rbx explore`: a box resting on a floor or an incline, launched along it (or
// left at rest on the incline), sliding to rest by Coulomb's law; drawn, realised as a scene with
// its closed form, judged and shrunk (comparisons/eval/explore.h).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/scene/scene_file.h"

namespace rbx {

using namespace explore_detail;

namespace {

// The least deceleration drawn, as a multiple of g (mu cos(theta) - sin(theta) at least this on
// an incline, so that the box sticks with margin after it stops; mu >= 0.1 on a floor).
constexpr double kLeastDeceleration = 0.1;
// After the closed-form rest the run goes on this long (s): a creep or a turn at rest shows.
constexpr double kSlideSettleTime = 0.2;
// Speed (m/s) along the surface below which the box counts as stopped (kSlideRestTimeMark), and
// the distance (m) it may then move for good: a library's resting jitter (Bullet hops by a few
// micrometres at a few mm/s now and then) is not a slide, and a creep past it is not a rest; a
// tenth of the position mark.
constexpr double kRestSpeed = 1e-3;
constexpr double kRestDrift = 1e-4;
// The box starts this far (m) into the surface. At exactly zero depth, the written pose's
// rounding puts the base's corners on an incline about 1e-16 m either side of the surface, so
// a library's first step found one or two corners, not the face, and their friction kicked the
// box aside or into a turn the closed form never has (ODE's and DART's only misses, and four of
// Bullet's, measured on seed 8086). A micrometre is far above that rounding and far below every
// mark (a tenth of a millimetre of rise, a millimetre of position).
constexpr double kStartDepth = 1e-6;

// The rotation about a horizontal axis that tilts +z by theta toward the fall line's heading
// `azimuth` (both radians): the incline's slab frame.
Quat incline_rotation(double theta, double azimuth) {
  const Vec3 axis(-std::sin(azimuth), std::cos(azimuth), 0.0);  // z x h
  return Quat(Eigen::AngleAxisd(theta, axis));
}

// The slab (a static box 1 m thick, its top through the origin), whole metres wide and reaching
// at least 0.5 m past the box's whole path.
ExploreBody slide_surface(const SlideSample& s) {
  ExploreBody e;
  e.shape_class = "box";
  const double reach = std::ceil(s.stop_distance + 0.5 * std::hypot(s.size.x(), s.size.y()) + 0.5);
  e.box_size = Vec3(2.0 * reach, 2.0 * reach, 1.0);
  if (s.incline_deg == 0.0) {
    e.position = Vec3(0.0, 0.0, -0.5);
    return e;
  }
  e.orientation = incline_rotation(s.incline_deg * M_PI / 180.0, s.azimuth_deg * M_PI / 180.0);
  e.position = -0.5 * (build_orientation(e) * Vec3::UnitZ());
  return e;
}

// The box at t = 0: resting on the surface (its base kStartDepth into the slab's top), turned by
// its yaw about the surface normal.
ExploreBody slide_box(const SlideSample& s, const ExploreBody& surface) {
  ExploreBody e;
  e.shape_class = "box";
  e.box_size = s.size;
  e.position = s.start_position;
  if (s.incline_deg == 0.0) {
    e.use_degrees = true;
    e.rotation_deg = Vec3(0.0, 0.0, s.yaw_deg);
  } else {
    const Quat yaw(Eigen::AngleAxisd(s.yaw_deg * M_PI / 180.0, Vec3::UnitZ()));
    e.orientation = (build_orientation(surface) * yaw).normalized();
  }
  return e;
}

}  // namespace

std::string slide_case(const SlideSample& s) {
  if (s.incline_deg == 0.0) return "floor";
  return s.along_fall_line > 0 ? "down" : s.along_fall_line < 0 ? "up" : "sticks";
}

double slide_rest_time(const Scene& scene) {
  const std::vector<RigidBody> bodies = make_bodies(scene);
  const Vec3 n = bodies[1].orientation * Vec3::UnitZ();
  const Vec3 v = bodies[0].velocity - bodies[0].velocity.dot(n) * n;
  const double speed = v.norm();
  if (speed == 0.0) return 0.0;
  const Vec3 g = scene.sim.gravity;
  const double pressing = -g.dot(n);  // the normal force per unit mass
  const Vec3 along = g - g.dot(n) * n;
  // Friction mu g_n against the motion; the in-plane gravity helps or hinders along it (the
  // scenes launch along the fall line, so the path stays straight).
  const double a = scene.sim.friction * pressing - along.dot(v / speed);
  return speed / a;
}

double measured_rest_time(const std::vector<StateSample>& samples, const Vec3& normal, double end) {
  const auto along = [&](const Vec3& x) { return Vec3(x - x.dot(normal) * normal); };
  // Backwards: a sample slower than kRestSpeed from which every later position stays within
  // kRestDrift of its own; the earliest such. Once two later positions are more than twice the
  // drift apart, no earlier sample can qualify.
  double t = end;
  std::vector<Vec3> later;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (size_t k = samples.size(); k-- > 0;) {
    const BodyFinal& b = samples[k].bodies[0];
    const Vec3 p = along(b.position);
    later.push_back(p);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    if ((hi - lo).norm() > 2.0 * std::sqrt(3.0) * kRestDrift) break;
    if (!(along(b.velocity).norm() < kRestSpeed)) continue;
    bool stays = true;
    for (size_t j = 0; stays && j < later.size(); ++j) stays = (later[j] - p).norm() <= kRestDrift;
    if (stays) t = samples[k].time;
  }
  return t;
}

bool hop_accounts_for_rest(const std::vector<StateSample>& samples, const Vec3& normal, double rest,
                           double closed_form, double friction, double deceleration, double rise) {
  if (!(rise > 0.1 * kSlideLiftMark) || !(deceleration > 0.0)) return false;
  // The last sample before the rest: the box still sliding, the step that stopped it not yet
  // taken (a landing's impulse there can stop it with friction to spare).
  const StateSample* last = nullptr;
  for (const StateSample& k : samples)
    if (k.time < rest) last = &k;
  if (last == nullptr) return false;
  const double shift = -friction * last->bodies[0].velocity.dot(normal) / deceleration;
  return std::abs(rest - closed_form - shift) <= kSlideRestTimeMark;
}

double largest_rise(const std::vector<StateSample>& samples, const Vec3& start, const Vec3& rest,
                    const Vec3& normal) {
  // A start within a tenth of the mark of the rest height is on the surface (a slide's, or a
  // written scene's rounding of it); a landing's starts a drop above.
  bool reached = (start - rest).dot(normal) <= 0.1 * kSlideLiftMark;
  double rise = 0.0;
  for (const StateSample& k : samples) {
    const double h = (k.bodies[0].position - rest).dot(normal);
    if (reached)
      rise = std::max(rise, h);
    else
      reached = h <= 0.1 * kSlideLiftMark;
  }
  return rise;
}

bool realize_slide(SlideSample& s) {
  s.text.clear();
  const double mu = s.friction, g = kGravity, theta = s.incline_deg * M_PI / 180.0;
  const double footprint = std::min(s.size.x(), s.size.y());
  if (!(s.size.minCoeff() > 0 && s.mass > 0 && mu > 0 && s.dt > 0 && s.speed >= 0 &&
        s.incline_deg >= 0 && s.incline_deg < 60 && std::abs(s.along_fall_line) <= 1))
    return false;
  if (!(mu * s.size.z() <= kNoTipMargin * footprint)) return false;  // could tip
  const double holds = mu * std::cos(theta) - std::sin(theta);       // static friction's margin
  if (!(holds >= kLeastDeceleration)) return false;
  // At rest exactly when it is an incline's resting case.
  const bool at_rest = s.incline_deg > 0 && s.along_fall_line == 0;
  if (at_rest != (s.speed == 0.0)) return false;
  // The surface as the loader builds it: its normal and fall line.
  s.stop_distance = 0.0;
  ExploreBody surface = slide_surface(s);
  s.normal = build_orientation(surface) * Vec3::UnitZ();
  const Vec3 fall = s.incline_deg > 0
                        ? Vec3((-Vec3::UnitZ() + s.normal.z() * s.normal).normalized())
                        : Vec3::Zero();
  const double heading = s.heading_deg * M_PI / 180.0;
  const Vec3 dir = s.incline_deg == 0 ? Vec3(std::cos(heading), std::sin(heading), 0.0)
                                      : Vec3(s.along_fall_line >= 0 ? fall : -fall);
  // The slide: friction mu g cos(theta) against the motion, gravity's g sin(theta) along the
  // fall line with it (down) or against it (up).
  s.deceleration = g * (mu * std::cos(theta) - std::sin(theta) * s.along_fall_line);
  if (s.incline_deg == 0) s.deceleration = mu * g;
  s.stop_distance = s.speed * s.speed / (2.0 * s.deceleration);
  s.rest_time = s.speed / s.deceleration;
  s.duration = std::ceil((s.rest_time + kSlideSettleTime) / s.dt) * s.dt;
  surface = slide_surface(s);  // sized for the path
  s.start_position = (0.5 * s.size.z() - kStartDepth) * s.normal;
  s.velocity = s.speed * dir;
  s.expect_position = s.start_position + s.stop_distance * dir;

  const std::string what = slide_case(s);
  std::ostringstream o;
  o << "description = \"rbx explore slide seed " << s.seed << " sample " << s.index << " ("
    << (what == "floor"    ? "on a floor"
        : what == "sticks" ? "at rest on an incline"
                           : what + " an incline")
    << ", mu = " << num(mu) << ")\"\n";
  o << "checks = [\"impulse\"]\n\n[sim]\ndt = " << num(s.dt) << "\nduration = " << num(s.duration)
    << "\ngravity = " << vec(Vec3(0.0, 0.0, -g)) << "\nrestitution = 0.0\nfriction = " << num(mu)
    << "\n\n";
  o << dynamic_body_text(slide_box(s, surface), "box", s.mass, s.velocity, false) << "\n"
    << dynamic_body_text(surface, "surface", 1.0, Vec3::Zero(), true);
  o << "\n# Closed form (rbx explore, slide kind; g = " << num(g) << " m/s^2, mu = " << num(mu)
    << ", incline theta = " << num(s.incline_deg) << " deg).\n"
    << "# The box rests on the surface at t = 0 (its base flat on it, " << num(kStartDepth)
    << " m into it), launched at v = " << num(s.speed) << " m/s\n# along " << vec(dir) << " ("
    << (what == "floor" ? "its heading"
        : what == "up"  ? "up the fall line"
                        : "down the fall line")
    << ").\n";
  if (what == "sticks")
    o << "# At rest on the incline: tan(theta) = " << num(std::tan(theta)) << " < mu, static "
      << "friction holds it; it stays where it is.\n";
  else
    o << "# Deceleration a = g (mu cos(theta) " << (what == "up" ? "+" : "-")
      << " sin(theta)) = " << num(s.deceleration) << " m/s^2 (on a floor mu g);\n"
      << "# it stops after v^2 / (2 a) = " << num(s.stop_distance)
      << " m at t = v / a = " << num(s.rest_time) << " s, and static friction\n"
      << "# holds it (mu cos(theta) - sin(theta) = " << num(holds) << " > 0).\n";
  o << "# No turn: mu sz = " << num(mu * s.size.z()) << " < min(sx, sy) = " << num(footprint)
    << " (the box cannot tip).\n# At t = duration: at rest, centre " << vec(s.expect_position)
    << ", orientation unchanged.\n";
  o << box_at_rest_expect("v", s.speed, s.dt, s.expect_position);
  s.text = o.str();
  return true;
}

SlideSample make_slide_sample(uint64_t seed, uint64_t index) {
  return first_realized<SlideSample>(seed, index, 20, "slide", [](SampleRng& r, SlideSample& s) {
    draw_box(r, s.friction, s.size, s.mass, s.yaw_deg, kNoTipMargin);
    // Floors on 2 samples in 5; inclines launched down, up or left at rest alike.
    if (r.uniform() < 0.4) {
      s.incline_deg = 0.0;
      s.heading_deg = r.uniform(0.0, 360.0);
    } else {
      // Up to where the box still sticks with margin: mu cos(theta) - sin(theta) >= 0.1.
      const double most =
          std::acos(std::min(1.0, kLeastDeceleration / std::hypot(s.friction, 1.0))) -
          std::atan2(1.0, s.friction);
      if (!(most > 2.0 * M_PI / 180.0)) return false;
      s.incline_deg = r.uniform(1.0, most * 180.0 / M_PI);
      s.azimuth_deg = r.uniform(0.0, 360.0);
      s.along_fall_line = r.integer(-1, 1);
    }
    // Speeds to 1.5 m/s (kLandingPositionMark says why).
    s.speed = r.uniform(0.05, 1.5);
    if (s.incline_deg > 0 && s.along_fall_line == 0) s.speed = 0.0;
    s.dt = 1e-3;
    return realize_slide(s);
  });
}

SampleOutcome evaluate_slide_sample(const SlideSample& s, const std::vector<std::string>& names,
                                    const std::vector<Backend>* table, const ResultCache* cache) {
  SampleOutcome out;
  out.index = s.index;
  out.pose_class = "slide";
  out.shapes = s.incline_deg == 0 ? "box-floor" : "box-incline";
  out.feature = slide_case(s);
  out.touching = true;
  const Scene scene = parse_scene(s.text, "explore.toml");
  const std::vector<RigidBody> inputs = make_bodies(scene);
  // The velocity error's energy scale: the launch's kinetic energy, or, for a box left at rest,
  // that of a 1 m/s slide (the error is then the energy of any motion it picks up).
  const double v2 = inputs[0].velocity.squaredNorm();
  const double e0 = 0.5 * inputs[0].mass * (v2 > 0 ? v2 : 1.0);
  const std::vector<std::optional<RefState>> ref = {RefState{Vec3::Zero(), Vec3::Zero()},
                                                    std::nullopt};
  const Vec3 n = s.normal;
  run_dynamics_subjects(
      scene, names, DynamicsOptions{0.0, 1}, table, cache, out,
      [&](BackendOutcome& o, const DynamicsResult& run) {
        const BodyFinal& f = run.finals[0];
        const Vec3 off = f.position - s.expect_position;
        o.position_err_m = (off - off.dot(n) * n).norm();  // along the surface
        o.turn_rad = rotation_angle(inputs[0].orientation, f.orientation);
        o.velocity_err_ke = ke_norm_error(inputs, run.finals, ref, e0);
        const double rest = measured_rest_time(run.samples, n, s.duration);
        o.rest_time_err_s = std::abs(rest - s.rest_time);
        if (!(o.turn_rad <= kLandingTurnMark))
          o.error = "turn";
        else if (!(o.position_err_m <= kLandingPositionMark))
          o.error = "position";
        else if (!(o.rest_time_err_s <= kSlideRestTimeMark))
          o.error = "rest_time";
        name_deep_contact(o, run, s.size.minCoeff());
        o.rise_m = largest_rise(run.samples, s.start_position, s.start_position, n);
        if (!o.error.empty() && o.error != "deep_contact" &&
            (o.rise_m > kSlideLiftMark ||
             (o.error == "rest_time" &&
              hop_accounts_for_rest(run.samples, n, rest, s.rest_time, s.friction, s.deceleration,
                                    o.rise_m))))
          o.error = "lift_off";
        name_cone_excess(o, run, off - off.dot(n) * n,
                         s.speed > 0.0 ? Vec3(s.velocity.normalized()) : Vec3::Zero(),
                         s.speed > 0.0 ? s.deceleration : 0.0, inputs[0].orientation, f.orientation,
                         n);
      });
  return out;
}

SlideShrinkResult shrink_slide(const SlideSample& start, const std::string& backend,
                               const std::string& sig, int max_evaluations) {
  DesignShrinker<SlideSample> k(start, backend, sig, max_evaluations, realize_slide,
                                [](const SlideSample& s, const std::vector<std::string>& names) {
                                  return evaluate_slide_sample(s, names);
                                });

  k.round_down(&SlideSample::mass, 1.0, {});
  k.round_down(&SlideSample::yaw_deg, 0.0, {90, 45, 15, 5, 1});
  k.round_down(&SlideSample::heading_deg, 0.0, {90, 45, 15, 5, 1});
  k.round_down(&SlideSample::azimuth_deg, 0.0, {90, 45, 15, 5, 1});
  k.round_down(&SlideSample::incline_deg, 0.0, {10, 5, 1});
  k.round_down(&SlideSample::friction, 0.5, {0.1, 0.05, 0.01});
  k.round_size();
  k.round_down(&SlideSample::speed, 1.0, {0.5, 0.1, 0.01});
  return k.template result<SlideShrinkResult>();
}

}  // namespace rbx
