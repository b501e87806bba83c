#include "comparisons/eval/impact_cause.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "engine/format.h"
#include "reference/exact.h"

namespace rbx {

std::string phase_text(const std::string& label) {
  if (label == "written") return "as written";
  return label.substr(0, 1) + "/" + label.substr(2) + " of a step later";
}

Cause impact_cause(const Scene& scene, const std::vector<RigidBody>& inputs,
                   const std::string& name, const FirstImpulse& fi,
                   const std::vector<RigidBody>& start, double written, double worst,
                   const std::string& worst_phase,
                   const std::vector<std::optional<RefState>>& expected) {
  Cause c;
  c.backend = name;
  c.scene = scene.name;
  std::ostringstream d;
  const std::string errors = "velocity error " + fmt_num(written, 2) + " as written" +
                             (worst_phase != "written" && worst > written
                                  ? ", " + fmt_num(worst, 2) + " " + phase_text(worst_phase)
                                  : std::string());
  if (!fi.seen) {
    c.kind = "no impulse applied";
    c.detail = errors;
    return c;
  }
  auto index = [&](const std::string& n) {
    for (size_t i = 0; i < inputs.size(); ++i)
      if (inputs[i].name == n) return static_cast<long>(i);
    return -1L;
  };
  const long ia = index(fi.body_a), ib = index(fi.body_b);
  bool spinning = false;
  for (const RigidBody& b : inputs) spinning = spinning || b.angular_velocity.norm() > 0.0;
  const double t = fi.step * scene.sim.dt;
  std::optional<SatResult> truth;
  if (ia >= 0 && ib >= 0 && !spinning) {
    auto placed = [&](long i) {
      RigidBody b = start[i];
      if (!b.is_static) b.position += b.velocity * t + 0.5 * scene.sim.gravity * t * t;
      return b;
    };
    const RigidBody a = placed(ia), b = placed(ib);
    truth = sat_query(*a.shape, a.pose(), *b.shape, b.pose());
  }
  d << fi.contact_points << (fi.contact_points == 1 ? " point" : " points");
  double angle = 0.0;
  size_t corners = 0;
  if (truth && truth->touching) {
    corners = truth->manifold.size();
    angle = std::acos(std::clamp(fi.normal.dot(truth->normal), -1.0, 1.0)) * 180.0 / M_PI;
    Vec3 centre = Vec3::Zero();
    for (const Vec3& p : truth->manifold) centre += p;
    if (corners) centre /= static_cast<double>(corners);
    const std::string what = corners >= 3 ? "face patch of " + std::to_string(corners) + " corners"
                             : corners == 2 ? "edge contact"
                                            : "single-point contact";
    d << " against a true " << what;
    // Where one point stands for the patch, how far from its centre (libraries that report
    // one event per pair give one of their points, not a mean).
    if (fi.contact_points == 1)
      d << ", " << fmt_num((fi.point - centre).norm(), 2) << " m from its centre";
    d << "; normal " << fmt_num(angle, 2) << "° off";
    // The closed-form impulse on the first body the [expect] block moves.
    for (long i : {ia, ib}) {
      const RigidBody& b = inputs[i];
      if (b.is_static || !expected[i] || !expected[i]->velocity) continue;
      const double j = std::abs(b.mass * (*expected[i]->velocity - b.velocity).dot(truth->normal));
      d << "; impulse in that step " << fmt_num(fi.impulse, 3) << " N s against " << fmt_num(j, 3)
        << " closed form";
      break;
    }
  } else {
    d << (spinning ? " (bodies spin: no free-flight truth)"
                   : " (the oracle sees no contact at those poses)");
  }
  d << "; first seen " << fmt_num(fi.depth, 2) << " m deep at step " << fi.step << " (entry phase "
    << fmt_num(fi.entry_phase, 2) << ")"
    << (written <= kMarkVelocityErr ? " in the run " + phase_text(worst_phase) : std::string())
    << "; " << errors;
  // The first measured sign, in this order: the normal, the manifold, the depth, else the
  // response itself.
  if (truth && truth->touching && angle > kMarkAngleDeg)
    c.kind = "normal off the truth at first impulse";
  else if (corners >= 3 && fi.contact_points == 1)
    c.kind = "one contact point on a face patch";
  else if (written <= kMarkVelocityErr && worst > kMarkVelocityErr)
    c.kind =
        "right only when contact begins on a step boundary: the response depends on the "
        "depth at detection";
  else if (fi.approach_speed > 0 && fi.depth > 0.5 * fi.approach_speed * scene.sim.dt)
    c.kind = "contact first seen deep (more than half a step of approach)";
  else
    c.kind = "contact seen as the truth (points, normal, depth): the error is in the response";
  c.detail = d.str();
  return c;
}

}  // namespace rbx
