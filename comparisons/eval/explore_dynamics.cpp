// The closed-form kinds of `rbx explore`: what the dynamics kinds share (a body as scene text,
// running the subjects, a box's rest as [expect]), and the impact kind, random single-point
// impacts drawn, realised as a scene with its closed form, judged and shrunk. The landing, slide
// and tunnel kinds have files of their own.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/measures.h"
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

std::string dynamic_body_text(const ExploreBody& e, const std::string& name, double mass,
                              const Vec3& velocity, bool is_static) {
  std::string t = body_text(e, name);
  std::ostringstream o;
  o << "mass = " << num(mass) << "\n";
  if (is_static)
    o << "static = true\n";
  else
    o << "velocity = " << vec(velocity) << "\n";
  return t + o.str();
}

void run_dynamics_subjects(
    const Scene& scene, const std::vector<std::string>& names, const DynamicsOptions& options,
    const std::vector<Backend>* table, const ResultCache* cache, SampleOutcome& out,
    const std::function<void(BackendOutcome&, const DynamicsResult&)>& judge) {
  const std::vector<RigidBody> bodies = cache ? make_bodies(scene) : std::vector<RigidBody>();
  for (const std::string& name : names) {
    const Backend* be = find_backend(name, table);
    if (!be || !be->dynamics) continue;
    DynamicsResult run = cache
                             ? run_dynamics(*be, scene, options.dt > 0 ? options.dt : scene.sim.dt,
                                            options.sample_every, *cache, bodies)
                                   .result
                             : run_dynamics_isolated(*be, scene, options).result;
    if (run.status == Status::Unsupported) continue;
    BackendOutcome o;
    o.backend = name;
    if (run.status == Status::Ok && run.finals.size() != scene.bodies.size()) {
      run.status = Status::Error;
      run.message = "returned " + std::to_string(run.finals.size()) + " final states";
    }
    if (run.status == Status::Error || run.status == Status::Timeout) {
      o.error = to_string(run.status);
      o.message = run.message;
    } else {
      o.measured = true;
      judge(o, run);
    }
    out.backends.push_back(o);
  }
}

void name_deep_contact(BackendOutcome& o, const DynamicsResult& run, double side) {
  if (run.laws.measured)
    o.reported_depth_m = run.laws.residuals[static_cast<size_t>(Law::Penetration)].worst;
  if (!o.error.empty() && o.reported_depth_m > 0.1 * side) o.error = "deep_contact";
}

void name_cone_excess(BackendOutcome& o, const DynamicsResult& run, const Vec3& off_surface,
                      const Vec3& slide_dir, double deceleration, const Quat& start,
                      const Quat& end, const Vec3& normal) {
  if (o.error != "turn" && o.error != "position") return;
  for (const ConeExcess& u : run.laws.cone_excess) {
    if (u.body != 0) continue;
    bool explains = false;
    if (o.turn_rad > kLandingTurnMark) {
      // The whole turn left once the excess's turn about the normal is taken back (a tilt or a
      // turn the other way stays).
      const Quat without = Quat(Eigen::AngleAxisd(-u.turn_rad, normal)) * end;
      explains = std::abs(u.turn_rad) >= 0.5 * o.turn_rad ||
                 rotation_angle(start, without) <= kLandingTurnMark;
    } else if (deceleration > 0.0) {
      const Vec3 shift = u.push_m2s2 / deceleration * slide_dir;
      explains = (off_surface - shift).norm() <= kLandingPositionMark;
    }
    if (explains) o.error = "cone_excess";
    return;
  }
}

std::string box_at_rest_expect(const std::string& speed_name, double speed, double dt,
                               const Vec3& position) {
  std::ostringstream o;
  o << "[expect]\nengines = [\"custom\", \"custom-seed\"]\nknown_failure = \"custom-seed: the seed "
       "omits friction and resting contact "
       "(seed correction 12 (what the seed admits it lacks)): the box slides on, or sinks\"\n"
       "# 1 mm (position; the explore mark), 1e-3 m/s and rad/s (at rest): a time-stepped slide\n"
       "# falls short of the integral by at most "
    << speed_name << " dt / 2 = " << num(0.5 * speed * dt)
    << " m.\ntolerance = " << num(kLandingPositionMark)
    << "\n[expect.body.box]\nposition = " << vec(position)
    << "\nvelocity = [0.0, 0.0, 0.0]\nangular_velocity = [0.0, 0.0, 0.0]\n";
  return o.str();
}

void draw_box(SampleRng& r, double& friction, Vec3& size, double& mass, double& yaw_deg,
              double no_tip_margin) {
  friction = r.uniform(0.1, 1.0);
  // Footprint sides 0.2 to 2 m; height up to 3 footprints, kept clear of tipping.
  size.x() = std::pow(10.0, r.uniform(-0.7, 0.3));
  size.y() = std::pow(10.0, r.uniform(-0.7, 0.3));
  const double footprint = std::min(size.x(), size.y());
  size.z() = footprint * r.uniform(0.1, std::min(3.0, no_tip_margin / friction));
  mass = std::pow(10.0, r.uniform(-1.0, 1.0));
  yaw_deg = r.uniform(0.0, 90.0);  // a box's yaw repeats every 90 degrees
}

}  // namespace explore_detail

// ---------------------------------------------------------------------------------------------
// Impact kind

namespace {

// Torque-free rotation: from orientation q, angular momentum L (world, constant) over time t;
// omega = R I^-1 R^T L, RK4 on the quaternion with steps of 1e-5 s (|omega h| < 1e-3 here, so
// the error is below 1e-12 per step; the closed form is the exact flight, not a library's).
Quat free_rotation(const Mat3& inverse_inertia_body, Quat q, const Vec3& L, double t) {
  if (t <= 0 || L.norm() == 0) return q;
  const int n = std::max(1, static_cast<int>(std::ceil(t / 1e-5)));
  const double h = t / n;
  auto deriv = [&](const Eigen::Vector4d& c) {
    const Quat qq = Quat(c[3], c[0], c[1], c[2]).normalized();
    const Mat3 R = qq.toRotationMatrix();
    const Vec3 w = R * inverse_inertia_body * R.transpose() * L;
    const Quat d = Quat(0.0, w.x(), w.y(), w.z()) * qq;
    return Eigen::Vector4d(0.5 * d.x(), 0.5 * d.y(), 0.5 * d.z(), 0.5 * d.w());
  };
  Eigen::Vector4d c = q.coeffs();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector4d k1 = deriv(c), k2 = deriv(c + 0.5 * h * k1), k3 = deriv(c + 0.5 * h * k2),
                          k4 = deriv(c + h * k3);
    c += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    c.normalize();
  }
  return Quat(c[3], c[0], c[1], c[2]).normalized();
}

std::string impact_text(const ImpactSample& s, const std::string& header, const std::string& tail) {
  std::ostringstream o;
  o << header;
  o << "description = \"rbx explore impact seed " << s.seed << " sample " << s.index << " ("
    << (s.b_static ? "on a static box" : "two free bodies") << ", e = " << num(s.restitution)
    << ")\"\n";
  o << "checks = [\"impulse\"]\n\n[sim]\ndt = " << num(s.dt) << "\nduration = " << num(s.duration)
    << "\nrestitution = " << num(s.restitution)
    << "\nfriction = 0.0\ngravity = [0.0, 0.0, 0.0]\n\n";
  o << dynamic_body_text(s.a, "A", s.mass_a, s.velocity_a, false) << "\n"
    << dynamic_body_text(s.b, "B", s.mass_b, s.velocity_b, s.b_static);
  if (!tail.empty()) o << "\n" << tail;
  return o.str();
}

// Scene bodies moved along their velocities by t (translation only: no spin before the impact).
std::vector<RigidBody> at_time(std::vector<RigidBody> bodies, double t) {
  for (RigidBody& b : bodies)
    if (!b.is_static) b.position += b.velocity * t;
  return bodies;
}

int impact_points(const ImpactSample& s) {
  return (s.a.shape_class == "box" ? 8 : static_cast<int>(s.a.points.size())) + 8;
}

// The closed form of a single-point impact with restitution e at point p (ra, rb from the
// centres) and normal n from B toward A (seed corrections: world-frame inverse inertia,
// velocity of the point): the impulse and every velocity and angular momentum after it.
struct SinglePointImpulse {
  double j = 0.0, vn = 0.0;  // impulse (N s), normal velocity before (m/s)
  Vec3 va, wa, vb, wb;       // velocities and angular velocities after
  Vec3 La, Lb;               // angular momenta after (B: zero when static)
};

SinglePointImpulse single_point_impulse(const RigidBody& A, const RigidBody& B, const Vec3& ra,
                                        const Vec3& rb, const Vec3& normal, double restitution) {
  SinglePointImpulse r;
  const Mat3 ia = A.inverse_inertia_world();
  const Mat3 ib = B.is_static ? Mat3::Zero() : B.inverse_inertia_world();
  const double inv_mb = B.is_static ? 0.0 : 1.0 / B.mass;
  const double k = 1.0 / A.mass + inv_mb + normal.dot((ia * ra.cross(normal)).cross(ra)) +
                   normal.dot((ib * rb.cross(normal)).cross(rb));
  r.vn = (A.velocity - B.velocity).dot(normal);
  r.j = -(1.0 + restitution) * r.vn / k;
  r.va = A.velocity + r.j / A.mass * normal;
  r.wa = ia * ra.cross(r.j * normal);
  r.vb = B.velocity - r.j * inv_mb * normal;
  r.wb = -(ib * rb.cross(r.j * normal));
  r.La = A.inertia_world() * r.wa;
  r.Lb = B.is_static ? Vec3::Zero() : Vec3(B.inertia_world() * r.wb);
  return r;
}

// Free flight after the impact for `flight` seconds: false at a second contact (checked at 20
// times); else the final orientations in qa, qb (torque-free rotation from L).
bool free_flight(double flight, const std::vector<RigidBody>& after, const RigidBody& A,
                 const RigidBody& B, const SinglePointImpulse& imp, double size, Quat& qa,
                 Quat& qb) {
  // The rotation is carried from one check to the next (the flight is autonomous: L is
  // constant), not integrated again from the start for each of the 20 checks.
  Quat ra = A.orientation, rb = B.orientation;
  for (int step = 1; step <= 20; ++step) {
    const double t = flight * step / 20.0;
    RigidBody a2 = after[0], b2 = after[1];
    a2.position += imp.va * t;
    ra = free_rotation(A.inverse_inertia_body, ra, imp.La, flight / 20.0);
    a2.orientation = ra;
    if (!B.is_static) {
      b2.position += imp.vb * t;
      rb = free_rotation(B.inverse_inertia_body, rb, imp.Lb, flight / 20.0);
      b2.orientation = rb;
    }
    const SatResult r = sat_query(*a2.shape, a2.pose(), *b2.shape, b2.pose());
    if (r.touching || r.depth > -1e-6 * size) return false;
    qa = a2.orientation;
    qb = b2.orientation;
  }
  return true;
}

// The leading comment of an impact scene: how its closed form was derived.
std::string impact_derivation(const ImpactSample& s, const Vec3& p, const Vec3& normal,
                              const SinglePointImpulse& imp) {
  std::ostringstream d;
  d << "# Closed form (rbx explore, impact kind): no spin before the impact, so the contact\n"
       "# pose is the start pose moved along the velocities: first contact at t = "
    << num(s.contact_time) << " s,\n# phase " << num(s.phase)
    << " of its step. The exact oracle's contact, one point (vertex of A on a face of B):\n"
    << "#   p = " << vec(p) << ", n = " << vec(normal) << " (from B toward A)\n"
    << "# j = -(1 + e) (v_rel . n) / (1/mA + 1/mB + n.((IA^-1 (rA x n)) x rA) + same for B)\n"
    << "#   = " << num(imp.j) << " N s (v_rel . n = " << num(imp.vn) << " m/s)\n"
    << "# v' = v + j n / m, w' = I^-1 (r x j n) (B: minus); after it, torque-free flight to t = "
    << num(s.duration)
    << " s\n# (angular momentum kept, w = R I^-1 R^T L, integrated by RK4 at "
       "1e-5 s); no second contact\n# (the exact oracle at 20 times of the flight).\n";
  return d.str();
}

// The [expect] block of an impact scene; `speed` is the relative speed before it.
std::string impact_expect(const ImpactSample& s, double speed, const SinglePointImpulse& imp,
                          bool b_static) {
  std::ostringstream x;
  x << "[expect]\n# The closed form is exact to round-off; 1e-3 of the speed is the harness's mark "
       "of a\n# clear velocity disagreement (0.1 % in the energy norm): below it, a "
       "deviation.\n";
  x << "tolerance = " << fmt_num(1e-3 * std::max(1e-9, speed), 3) << "\n";
  x << "[expect.body.A]\nvelocity = " << vec(imp.va)
    << "\nangular_velocity = " << vec(s.expect_angular_velocity[0]) << "\n";
  if (!b_static)
    x << "[expect.body.B]\nvelocity = " << vec(imp.vb)
      << "\nangular_velocity = " << vec(s.expect_angular_velocity[1]) << "\n";
  return x.str();
}

}  // namespace

bool realize_impact(ImpactSample& s) {
  s.text.clear();
  if (s.b_static) s.velocity_b = Vec3::Zero();
  // 1. Poses at the contact time: B's box centre at the origin, A's lowest vertex along B's face
  //    normal put on the chosen point of that face.
  ImpactSample c = s;
  c.a.position = Vec3::Zero();
  c.b.position = Vec3::Zero();
  std::vector<RigidBody> bodies;
  try {
    bodies = make_bodies(parse_scene(impact_text(c, "", ""), "explore.toml"));
  } catch (const std::exception&) {
    return false;
  }
  const RigidBody& A0 = bodies[0];
  const RigidBody& B0 = bodies[1];
  const int axis = s.face % 3;
  const double sign = s.face < 3 ? 1.0 : -1.0;
  Vec3 local_n = Vec3::Zero();
  local_n[axis] = sign;
  const Vec3 n = B0.orientation * local_n;  // from B toward A
  Vec3 local_c = Vec3::Zero();
  local_c[axis] = 0.5 * sign * s.b.box_size[axis];
  local_c[(axis + 1) % 3] = s.face_u * s.b.box_size[(axis + 1) % 3];
  local_c[(axis + 2) % 3] = s.face_v * s.b.box_size[(axis + 2) % 3];
  const Vec3 point = B0.pose().apply(local_c);
  const double size_a = shape_size(*A0.shape);
  const double size = std::min(size_a, shape_size(*B0.shape));
  int lowest = -1;
  double low = 1e300, second = 1e300;
  for (int i = 0; i < static_cast<int>(A0.shape->vertices().size()); ++i) {
    const double d = A0.world_vertex(i).dot(n);
    if (d < low) {
      second = low;
      low = d;
      lowest = i;
    } else if (d < second) {
      second = d;
    }
  }
  // One vertex clearly lowest (3 % of A's size below the next): a single contact point that
  // stays single over the step a backend takes to see it.
  if (lowest < 0 || second - low < 0.03 * size_a) return false;
  // The point inside the face by a margin (fractions below 0.4 of the face).
  if (std::abs(s.face_u) > 0.4 || std::abs(s.face_v) > 0.4) return false;
  const Vec3 shift = point - A0.world_vertex(lowest);
  // Approaching along the normal, by at least a tenth of the relative speed.
  const Vec3 v_rel = s.velocity_a - s.velocity_b;
  if (!(v_rel.dot(n) < -0.1 * v_rel.norm())) return false;
  // 2. Back along the velocities by the contact time.
  s.a.position = shift - s.velocity_a * s.contact_time;
  s.b.position = -s.velocity_b * s.contact_time;
  s.phase = s.contact_time / s.dt - std::floor(s.contact_time / s.dt);
  const std::string body_text0 = impact_text(s, "", "");
  try {
    bodies = make_bodies(parse_scene(body_text0, "explore.toml"));
  } catch (const std::exception&) {
    return false;
  }
  const RigidBody& A = bodies[0];
  const RigidBody& B = bodies[1];
  // 3. The exact oracle: separated just before the contact time, one point just after it.
  const double approach = -v_rel.dot(n);
  {
    const auto before = at_time(bodies, s.contact_time - 1e-3 * s.dt);
    const SatResult sb =
        sat_query(*before[0].shape, before[0].pose(), *before[1].shape, before[1].pose());
    if (sb.touching && sb.depth >= 0) return false;
  }
  const auto after = at_time(bodies, s.contact_time + 1e-7 * size / approach);
  const SatResult sat =
      sat_query(*after[0].shape, after[0].pose(), *after[1].shape, after[1].pose());
  if (!sat.touching || sat.manifold.empty() || sat.normal.dot(n) < 1.0 - 1e-9) return false;
  Vec3 p = Vec3::Zero();
  for (const Vec3& m : sat.manifold) p += m;
  p /= static_cast<double>(sat.manifold.size());
  for (const Vec3& m : sat.manifold)
    if ((m - p).norm() > 1e-6 * size) return false;  // not a single point
  const Vec3 normal = sat.normal;
  // 4. The closed form at exact's point and normal; 5. free flight to the end.
  const SinglePointImpulse imp = single_point_impulse(A, B, p - after[0].position,
                                                      p - after[1].position, normal, s.restitution);
  Quat qa = A.orientation, qb = B.orientation;
  if (!free_flight(s.duration - s.contact_time, after, A, B, imp, size, qa, qb)) return false;
  auto spin = [](const RigidBody& b, const Quat& q, const Vec3& L) {
    const Mat3 R = q.toRotationMatrix();
    return Vec3(R * b.inverse_inertia_body * R.transpose() * L);
  };
  s.expect_velocity[0] = imp.va;
  s.expect_angular_velocity[0] = spin(A, qa, imp.La);
  s.expect_angular_momentum[0] = imp.La;
  s.expect_velocity[1] = imp.vb;
  s.expect_angular_velocity[1] = B.is_static ? Vec3::Zero() : spin(B, qb, imp.Lb);
  s.expect_angular_momentum[1] = imp.Lb;
  // 6. The scene with its derivation and [expect].
  s.derivation = impact_derivation(s, p, normal, imp);
  s.text = impact_text(s, "", s.derivation + impact_expect(s, v_rel.norm(), imp, B.is_static));
  return true;
}

ImpactSample make_impact_sample(uint64_t seed, uint64_t index) {
  return first_realized<ImpactSample>(
      seed, index, 30, "single-point impact", [](SampleRng& r, ImpactSample& s) {
        s.b_static = r.uniform() < 0.4;
        const double scale = std::pow(10.0, r.uniform(-0.3, 0.3));
        // A: a box or a hull of 4 to 60 points (a sliver's lowest vertex is rarely unique).
        do {
          s.a = random_body(r, scale);
        } while (s.a.shape_class == "sliver" || s.a.points.size() > 60);
        s.a.orientation = r.rotation();
        // B: a box, a slab under A when static, else up to 3 times A's size.
        s.b.shape_class = "box";
        if (s.b_static)
          s.b.box_size = Vec3(4 * scale, 4 * scale, scale);
        else
          for (int k = 0; k < 3; ++k) s.b.box_size[k] = scale * r.uniform(1.0, 3.0);
        s.b.orientation = r.rotation();
        s.mass_a = std::pow(10.0, r.uniform(-0.5, 0.5));
        s.mass_b = s.b_static ? 1.0 : std::pow(10.0, r.uniform(-0.5, 0.5));
        s.restitution = r.uniform(0.2, 1.0);
        s.dt = 1e-3;
        s.face = s.b_static ? 2 : r.integer(0, 5);
        s.face_u = r.uniform(-0.3, 0.3);
        s.face_v = r.uniform(-0.3, 0.3);
        // Relative velocity: against the face normal, tilted up to 30 degrees; 0.5 to 3 m/s.
        Vec3 local_n = Vec3::Zero();
        local_n[s.face % 3] = s.face < 3 ? 1.0 : -1.0;
        const Vec3 n = s.b.orientation.normalized() * local_n;
        const Vec3 t = n.cross(r.direction()).normalized();
        const double tilt = r.uniform(0.0, 30.0) * M_PI / 180.0;
        const Vec3 v_rel = r.uniform(0.5, 3.0) * (-std::cos(tilt) * n + std::sin(tilt) * t);
        if (s.b_static) {
          s.velocity_a = v_rel;
        } else {
          // Centre-of-mass velocity up to 1 m/s, split by the masses.
          const Vec3 vcm = r.uniform(0.0, 1.0) * r.direction();
          const double m = s.mass_a + s.mass_b;
          s.velocity_a = vcm + v_rel * (s.mass_b / m);
          s.velocity_b = vcm - v_rel * (s.mass_a / m);
        }
        // First contact 2 to 5 steps ahead, at a random phase of its step; then at least 50 ms of
        // flight, to a whole number of steps (a scene's duration is one).
        // The step count first, then the phase: two statements, since the order of a sum's
        // operands is the compiler's.
        const int steps_ahead = r.integer(2, 5);
        s.contact_time = (steps_ahead + r.uniform(0.02, 0.98)) * s.dt;
        s.duration = std::ceil((s.contact_time + 0.05) / s.dt) * s.dt;
        return realize_impact(s);
      });
}

SampleOutcome evaluate_impact_sample(const ImpactSample& s, const std::vector<std::string>& names,
                                     const std::vector<Backend>* table, const ResultCache* cache) {
  SampleOutcome out;
  out.index = s.index;
  out.pose_class = s.b_static ? "static" : "free";
  out.shapes = s.a.shape_class + "-" + (s.b_static ? "static" : "box");
  out.feature = "vertex_face";
  out.touching = true;
  out.phase = s.phase;
  const Scene scene = parse_scene(s.text, "explore.toml");
  const std::vector<RigidBody> inputs = make_bodies(scene);
  double e0 = 0.0;
  for (const RigidBody& b : inputs)
    if (!b.is_static) e0 += 0.5 * b.mass * b.velocity.squaredNorm();
  std::vector<std::optional<RefState>> ref(2);
  double e_ref = 0.0;
  for (int i = 0; i < 2; ++i) {
    if (inputs[i].is_static) continue;
    ref[i] = RefState{s.expect_velocity[i], s.expect_angular_velocity[i]};
    e_ref += 0.5 * inputs[i].mass * s.expect_velocity[i].squaredNorm() +
             0.5 * s.expect_angular_velocity[i].dot(s.expect_angular_momentum[i]);
  }
  if (e_ref < 1e-12 * e0) e_ref = e0;
  run_dynamics_subjects(
      scene, names, DynamicsOptions{0.0, 0}, table, cache, out,
      [&](BackendOutcome& o, const DynamicsResult& run) {
        o.velocity_err_ke = ke_norm_error(inputs, run.finals, ref, e0);
        // The same norm on momenta: p and L about the COM are what the impulse sets and the flight
        // keeps, so this error is the impulse's alone, whatever the library's free rotation does.
        double num_p = 0.0;
        for (int i = 0; i < 2; ++i) {
          if (inputs[i].is_static) continue;
          const BodyFinal& f = run.finals[i];
          const Mat3 R = f.orientation.toRotationMatrix();
          const Mat3 inv_i = R * inputs[i].inverse_inertia_body * R.transpose();
          const Mat3 inertia = R * inputs[i].inertia_body * R.transpose();
          const Vec3 dp = inputs[i].mass * (f.velocity - s.expect_velocity[i]);
          const Vec3 dl = inertia * f.angular_velocity - s.expect_angular_momentum[i];
          num_p += dp.squaredNorm() / inputs[i].mass + dl.dot(inv_i * dl);
        }
        o.momentum_err_ke = std::sqrt(num_p / (2.0 * e_ref));
        const double v0 = s.velocity_a.norm();
        if ((run.finals[0].velocity - s.velocity_a).norm() <= 1e-9 * v0 &&
            run.finals[0].angular_velocity.norm() <= 1e-9 * v0 / shape_size(*inputs[0].shape))
          o.error = "missed";  // A flew on untouched
        else if (!(o.momentum_err_ke <= kMarkVelocityErr))
          o.error = "impulse";
        else if (!(o.velocity_err_ke <= kMarkVelocityErr))
          o.error = "spin";  // the impulse is right; the free rotation after it is not
      });
  return out;
}

ImpactShrinkResult shrink_impact(const ImpactSample& start, const std::string& backend,
                                 const std::string& sig, int max_evaluations) {
  DesignShrinker<ImpactSample> k(start, backend, sig, max_evaluations, realize_impact,
                                 [](const ImpactSample& s, const std::vector<std::string>& names) {
                                   return evaluate_impact_sample(s, names);
                                 });
  // 1. Fewer points of A: its hull's own vertices, then chunks (halves first).
  if (k.sample.a.shape_class != "box") {
    ImpactSample c = k.sample;
    try {
      c.a.points = convex_hull(c.a.points).vertices();
      if (c.a.points.size() < k.sample.a.points.size()) k.accept(c);
    } catch (const std::exception&) {
    }
    for (size_t chunk = k.sample.a.points.size() / 2; chunk >= 1; chunk /= 2) {
      for (size_t at = 0; at < k.sample.a.points.size() && k.sample.a.points.size() > 4;) {
        ImpactSample d = k.sample;
        auto& p = d.a.points;
        const size_t end = std::min(at + chunk, p.size());
        if (p.size() - (end - at) < 4) break;
        p.erase(p.begin() + at, p.begin() + end);
        if (!k.accept(d)) at += chunk;
      }
      if (k.evaluations >= k.max_evaluations) break;
    }
  }
  // 2. Round numbers: e, masses, the point on the face, velocities.
  for (double e : {1.0, 0.5}) {
    ImpactSample c = k.sample;
    c.restitution = e;
    if (k.accept(c)) break;
  }
  {
    ImpactSample c = k.sample;
    c.mass_a = 1.0;
    c.mass_b = 1.0;
    k.accept(c);
  }
  {
    ImpactSample c = k.sample;
    c.face_u = c.face_v = 0.0;
    if (!k.accept(c)) {
      c.face_u = std::round(k.sample.face_u * 10) / 10;
      c.face_v = std::round(k.sample.face_v * 10) / 10;
      k.accept(c);
    }
  }
  for (double g : {0.5, 0.1, 0.01}) {
    ImpactSample c = k.sample;
    c.velocity_a = round_to(c.velocity_a, g);
    c.velocity_b = round_to(c.velocity_b, g);
    if (k.accept(c)) break;
  }
  // 3. Rotations toward axis-aligned, coarsest grid first.
  const double grids_deg[] = {90, 45, 15, 5, 1, 0.1};
  for (ExploreBody ImpactSample::*body : {&ImpactSample::a, &ImpactSample::b}) {
    const Vec3 deg = euler_deg(build_orientation(k.sample.*body));
    for (double g : grids_deg) {
      ImpactSample d = k.sample;
      (d.*body).use_degrees = true;
      (d.*body).rotation_deg = round_to(deg, g);
      if (k.accept(d)) break;
    }
  }
  ImpactShrinkResult r;
  r.vertices_before = impact_points(start);
  r.vertices_after = impact_points(k.sample);
  r.outcome = k.finish();
  r.sample = k.sample;
  r.steps_accepted = k.steps_accepted;
  r.evaluations = k.evaluations;
  return r;
}

}  // namespace rbx
