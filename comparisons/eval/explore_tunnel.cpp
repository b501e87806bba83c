// The tunnel kind of `rbx explore`: a box projectile, face-on, so fast that a step can carry it
// past a thin wall; drawn, realised as a scene with its closed form, judged and shrunk
// (comparisons/eval/explore.h).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/scene/scene_file.h"

namespace rbx {

using namespace explore_detail;

namespace {

// Steps run after the contact's step: the bounce is long over, the box well clear (or through).
constexpr int kStepsAfter = 10;

// The wall's frame: its local z along the near face's normal.
Quat wall_rotation(const Vec3& normal) {
  return Quat::FromTwoVectors(Vec3::UnitZ(), normal.normalized());
}

// The wall: a static slab `wall_thickness` thick, its near face through the origin, wide enough
// for the box's whole slide along it.
ExploreBody tunnel_wall(const TunnelSample& s) {
  ExploreBody e;
  e.shape_class = "box";
  const double along = std::abs(s.tangential) * s.speed * s.duration + s.size.maxCoeff() + 1.0;
  e.box_size = Vec3(2.0 * std::ceil(along), 2.0 * std::ceil(along), s.wall_thickness);
  e.orientation = wall_rotation(s.normal);
  e.position = -0.5 * s.wall_thickness * (build_orientation(e) * Vec3::UnitZ());
  return e;
}

ExploreBody tunnel_box(const TunnelSample& s) {
  ExploreBody e;
  e.shape_class = "box";
  e.box_size = s.size;
  const Quat yaw(Eigen::AngleAxisd(s.yaw_deg * M_PI / 180.0, Vec3::UnitZ()));
  e.orientation = (wall_rotation(s.normal) * yaw).normalized();
  e.position = s.start_position;
  return e;
}

}  // namespace

bool realize_tunnel(TunnelSample& s) {
  s.text.clear();
  if (!(s.size.minCoeff() > 0 && s.mass > 0 && s.wall_thickness > 0 && s.travel_ratio > 0 &&
        s.restitution >= 0 && s.restitution <= 1 && s.dt > 0 && s.steps_before >= 1 &&
        s.phase >= 0.02 && s.phase <= 0.98 && std::abs(s.tangential) <= 1 && s.normal.norm() > 0.5))
    return false;
  s.normal.normalize();
  // The near face's normal and the wall's x axis as the loader builds them.
  ExploreBody frame;
  frame.orientation = wall_rotation(s.normal);
  const Quat wall = build_orientation(frame);
  const Vec3 n = wall * Vec3::UnitZ(), t = wall * Vec3::UnitX();
  const double depth = s.size.z();
  s.speed = s.travel_ratio * (s.wall_thickness + depth) / s.dt;
  s.contact_time = (s.steps_before + s.phase) * s.dt;
  s.duration = (s.steps_before + 1 + kStepsAfter) * s.dt;
  s.velocity = -s.speed * n + s.tangential * s.speed * t;
  // Face-on, through the centre: the normal velocity reversed times e, the tangential kept (no
  // friction), no spin.
  s.velocity_after = s.restitution * s.speed * n + s.tangential * s.speed * t;
  const Vec3 at_contact = 0.5 * depth * n;
  s.start_position = at_contact - s.velocity * s.contact_time;
  s.expect_position = at_contact + s.velocity_after * (s.duration - s.contact_time);

  std::ostringstream o;
  o << "description = \"rbx explore tunnel seed " << s.seed << " sample " << s.index << " ("
    << num(s.travel_ratio) << " x the wall and box per step, e = " << num(s.restitution) << ")\"\n";
  o << "checks = [\"impulse\"]\n\n[sim]\ndt = " << num(s.dt) << "\nduration = " << num(s.duration)
    << "\nrestitution = " << num(s.restitution)
    << "\nfriction = 0.0\ngravity = [0.0, 0.0, 0.0]\n\n";
  o << dynamic_body_text(tunnel_box(s), "A", s.mass, s.velocity, false) << "\n"
    << dynamic_body_text(tunnel_wall(s), "wall", 1.0, Vec3::Zero(), true);
  o << "\n# Closed form (rbx explore, tunnel kind). The box flies face-on at the wall's near face "
       "(through\n# the origin, normal "
    << vec(n) << ") at " << num(s.speed) << " m/s along the normal; in one step it\n# travels "
    << num(s.travel_ratio) << " x (wall " << num(s.wall_thickness) << " m + box depth "
    << num(depth) << " m). First touch at t_c = (k + phase) dt = " << num(s.contact_time)
    << " s\n# (k = " << s.steps_before << ", phase " << num(s.phase)
    << "), face on face, the impulse through the centre: v' = e vn n + v_t =\n# "
    << vec(s.velocity_after) << " m/s, no spin; at t = duration the centre is at\n# "
    << vec(s.expect_position) << ", on the near side.\n";
  o << "[expect]\n# The closed form is exact to round-off; 1e-3 of the speed is the harness's mark "
       "of a clear\n# velocity disagreement (0.1 % in the energy norm).\n";
  o << "tolerance = " << num(1e-3 * s.speed)
    << "\n[expect.body.A]\nvelocity = " << vec(s.velocity_after)
    << "\nangular_velocity = [0.0, 0.0, 0.0]\n";
  s.text = o.str();
  return true;
}

TunnelSample make_tunnel_sample(uint64_t seed, uint64_t index) {
  return first_realized<TunnelSample>(seed, index, 10, "tunnel", [](SampleRng& r, TunnelSample& s) {
    // A box of sides 0.05 to 0.5 m, 0.1 to 10 kg, face-on; a wall 1 to 10 cm thick, any way up.
    for (int i = 0; i < 3; ++i) s.size[i] = std::pow(10.0, r.uniform(-1.3, -0.3));
    s.mass = std::pow(10.0, r.uniform(-1.0, 1.0));
    s.yaw_deg = r.uniform(0.0, 90.0);
    s.wall_thickness = std::pow(10.0, r.uniform(-2.0, -1.0));
    s.normal = r.rotation() * Vec3::UnitZ();
    // 0.2 to 20 times the wall and the box per step, log-uniform: half of them can step over.
    s.travel_ratio = std::pow(10.0, r.uniform(std::log10(0.2), std::log10(20.0)));
    s.tangential = r.uniform(-0.5, 0.5);
    s.restitution = r.uniform(0.0, 1.0);
    s.dt = 1e-3;
    s.steps_before = r.integer(2, 5);
    s.phase = r.uniform(0.02, 0.98);
    return realize_tunnel(s);
  });
}

SampleOutcome evaluate_tunnel_sample(const TunnelSample& s, const std::vector<std::string>& names,
                                     const std::vector<Backend>* table, const ResultCache* cache) {
  SampleOutcome out;
  out.index = s.index;
  out.pose_class = "tunnel";
  out.shapes = "box-wall";
  // Whether one step can carry the box from in front of the wall to behind it.
  out.feature = s.travel_ratio > 1.0 ? "fast" : "slow";
  out.touching = true;
  out.phase = s.phase;
  const Scene scene = parse_scene(s.text, "explore.toml");
  const std::vector<RigidBody> inputs = make_bodies(scene);
  const double e0 = 0.5 * inputs[0].mass * inputs[0].velocity.squaredNorm();
  const std::vector<std::optional<RefState>> ref = {RefState{s.velocity_after, Vec3::Zero()},
                                                    std::nullopt};
  const Vec3 n = inputs[1].orientation * Vec3::UnitZ();
  run_dynamics_subjects(scene, names, DynamicsOptions{}, table, cache, out,
                        [&](BackendOutcome& o, const DynamicsResult& run) {
                          const BodyFinal& f = run.finals[0];
                          o.velocity_err_ke = ke_norm_error(inputs, run.finals, ref, e0);
                          o.position_err_m = (f.position - s.expect_position).norm();
                          if (!(f.position.dot(n) >= 0.0))
                            o.error = "tunnel";
                          else if (!(o.velocity_err_ke <= kMarkVelocityErr))
                            o.error = "velocity";
                        });
  return out;
}

TunnelShrinkResult shrink_tunnel(const TunnelSample& start, const std::string& backend,
                                 const std::string& sig, int max_evaluations) {
  DesignShrinker<TunnelSample> k(start, backend, sig, max_evaluations, realize_tunnel,
                                 [](const TunnelSample& s, const std::vector<std::string>& names) {
                                   return evaluate_tunnel_sample(s, names);
                                 });
  k.round_down(&TunnelSample::mass, 1.0, {});
  k.round_down(&TunnelSample::yaw_deg, 0.0, {90, 45, 15, 5, 1});
  TunnelSample up = k.sample;
  up.normal = Vec3::UnitZ();
  if (up.normal != k.sample.normal) k.accept(up);
  k.round_down(&TunnelSample::tangential, 0.0, {0.1, 0.01});
  k.round_down(&TunnelSample::restitution, 0.5, {0.1, 0.01});
  TunnelSample cube = k.sample;
  cube.size = Vec3::Constant(0.1);
  if (cube.size != k.sample.size && !k.accept(cube))
    for (double g : {0.1, 0.05, 0.01}) {
      TunnelSample c = k.sample;
      c.size = round_to(c.size, g);
      if (c.size == k.sample.size || k.accept(c)) break;
    }
  k.round_down(&TunnelSample::wall_thickness, 0.05, {0.01});
  k.round_down(&TunnelSample::travel_ratio, 2.0, {1, 0.5, 0.1});
  k.round_down(&TunnelSample::phase, 0.5, {0.1, 0.01});
  return k.template result<TunnelShrinkResult>();
}

}  // namespace rbx
