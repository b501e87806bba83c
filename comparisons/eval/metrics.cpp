#include "comparisons/eval/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "comparisons/eval/contact_eval.h"
#include "engine/detect.h"
#include "engine/format.h"

namespace rbx {

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double sorted_quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double at = q * static_cast<double>(sorted.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(at));
  const size_t hi = std::min(sorted.size() - 1, lo + 1);
  return sorted[lo] + (at - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

namespace {

// World inertia of body b at a final orientation.
Mat3 world_inertia(const RigidBody& b, const Quat& q) {
  const Mat3 rot = q.toRotationMatrix();
  return rot * b.inertia_body * rot.transpose();
}

}  // namespace

double ke_norm_error(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& finals,
                     const std::vector<std::optional<RefState>>& ref, double fallback_energy) {
  double num = 0.0, e_ref = 0.0;
  for (size_t i = 0; i < inputs.size() && i < finals.size() && i < ref.size(); ++i) {
    if (!ref[i] || inputs[i].is_static) continue;
    const RigidBody& b = inputs[i];
    const Mat3 inertia = world_inertia(b, finals[i].orientation);
    if (ref[i]->velocity) {
      num += b.mass * (finals[i].velocity - *ref[i]->velocity).squaredNorm();
      e_ref += 0.5 * b.mass * ref[i]->velocity->squaredNorm();
    }
    if (ref[i]->angular_velocity) {
      const Vec3 dw = finals[i].angular_velocity - *ref[i]->angular_velocity;
      num += dw.dot(inertia * dw);
      e_ref += 0.5 * ref[i]->angular_velocity->dot(inertia * *ref[i]->angular_velocity);
    }
  }
  // A reference at rest (e = 0 head-on in the centre-of-mass frame) has no energy to compare
  // with: fall back to the initial kinetic energy.
  if (e_ref < 1e-12 * fallback_energy) e_ref = fallback_energy;
  if (!(e_ref > 0.0)) return std::sqrt(num);
  return std::sqrt(num / (2.0 * e_ref));
}

double kinetic_energy(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& s) {
  double e = 0.0;
  for (size_t i = 0; i < inputs.size() && i < s.size(); ++i) {
    const RigidBody& b = inputs[i];
    if (b.is_static) continue;
    e +=
        0.5 * b.mass * s[i].velocity.squaredNorm() +
        0.5 * s[i].angular_velocity.dot(world_inertia(b, s[i].orientation) * s[i].angular_velocity);
  }
  return e;
}

double total_energy(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& s,
                    const Vec3& gravity) {
  double e = kinetic_energy(inputs, s);
  for (size_t i = 0; i < inputs.size() && i < s.size(); ++i)
    if (!inputs[i].is_static) e -= inputs[i].mass * gravity.dot(s[i].position);
  return e;
}

std::optional<double> expected_kinetic_energy(const std::vector<RigidBody>& inputs,
                                              const std::vector<BodyFinal>& finals,
                                              const std::vector<std::optional<RefState>>& ref) {
  // Every moving body needs both velocities: a partial closed form says nothing about the rest.
  double e = 0.0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    const RigidBody& b = inputs[i];
    if (b.is_static) continue;
    if (i >= ref.size() || i >= finals.size() || !ref[i] || !ref[i]->velocity ||
        !ref[i]->angular_velocity)
      return std::nullopt;
    const Vec3& w = *ref[i]->angular_velocity;
    e += 0.5 * b.mass * ref[i]->velocity->squaredNorm() +
         0.5 * w.dot(world_inertia(b, finals[i].orientation) * w);
  }
  return e;
}

EnergyError energy_error(double e0, double e1, double ke_final, std::optional<double> ke_expected,
                         double restitution, double scale) {
  if (!(scale > 0.0)) return {0.0, "invariant"};
  // A closed form fixes the final kinetic energy: any difference, loss or gain, is an error.
  if (ke_expected) return {std::abs(ke_final - *ke_expected) / scale, "analytic"};
  // Without one: e = 1 allows no change; e < 1 allows a loss but never a gain.
  const double change = (e1 - e0) / scale;
  return {restitution >= 1.0 ? std::abs(change) : std::max(change, 0.0), "invariant"};
}

double distance_to_region(const Vec3& p, const std::vector<Vec3>& poly) {
  if (poly.empty()) return std::numeric_limits<double>::infinity();
  // Nearest point on the outline (edges; a point or a segment is its own outline).
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[(i + 1) % poly.size()];
    const Vec3 ab = b - a;
    const double t =
        ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    best = std::min(best, (a + t * ab - p).norm());
  }
  if (poly.size() >= 3) {
    // Inside the polygon's outline: the distance is the height above its plane.
    Vec3 c = Vec3::Zero();
    for (const Vec3& v : poly) c += v;
    c /= static_cast<double>(poly.size());
    Vec3 n = Vec3::Zero();
    for (size_t i = 0; i < poly.size(); ++i)
      n += (poly[i] - c).cross(poly[(i + 1) % poly.size()] - c);
    if (n.norm() > 0) {
      n.normalize();
      const Vec3 q = p - n * n.dot(p - c);
      bool inside = true;
      for (size_t i = 0; i < poly.size() && inside; ++i)
        inside = (poly[(i + 1) % poly.size()] - poly[i]).cross(q - poly[i]).dot(n) >= -1e-12;
      if (inside) best = std::min(best, std::abs(n.dot(p - c)));
    }
  }
  return best;
}

double contact_point_error(const Vec3& p, const RigidBody& a, const RigidBody& b,
                           const std::vector<Vec3>& manifold) {
  // Distance to the union of the intersection volume and the manifold hull: 0 inside both
  // bodies (the engine's round-off tolerance, 1e-9 of the larger shape, so points on a shared
  // face count), else the distance to the manifold, an upper bound on the distance to the union.
  const double tol = point_in_mesh_tolerance(*a.shape, *b.shape);
  if (point_in_mesh(*a.shape, a.pose(), p, tol) && point_in_mesh(*b.shape, b.pose(), p, tol))
    return 0.0;
  return distance_to_region(p, manifold);
}

double touching_error(const ContactResult& r, bool true_touching) {
  return (deepest(r) != nullptr) == true_touching ? 0.0 : 1.0;
}

StabilityVerdict stability_verdict(const StabilityFacts& f) {
  StabilityVerdict v;
  std::vector<std::string> unstable, sinks, dissipative;
  // Unstable: no energy source exists in these scenes (e <= 1, no motors), so a gain beyond 1 %
  // is the integrator's or the contact solver's; so are non-finite states, tunnelling, a run
  // stopped by a guard, momentum drift in a closed system and penetration past half a body.
  if (f.nonfinite) unstable.push_back("non-finite state");
  if (f.energy_made_j > 0 && f.energy_growth > kUnstableEnergyGrowth)
    unstable.push_back("energy from nothing: the bodies started still and the run gave them " +
                       fmt_num(f.energy_made_j, 3) + " J");
  else if (f.energy_growth > kUnstableEnergyGrowth)
    unstable.push_back("energy grew by " + fmt_num(100 * f.energy_growth, 3) + " %");
  if (f.tunnelled_pairs)
    unstable.push_back(std::to_string(f.tunnelled_pairs) + " pair(s) tunnelled");
  if (f.stopped) unstable.push_back(f.stop_message);
  if (f.closed && f.momentum_drift > 1e-6)
    unstable.push_back("momentum drift " + fmt_num(f.momentum_drift, 3));
  if (f.max_penetration > 0.5)
    unstable.push_back("penetration " + fmt_num(100 * f.max_penetration, 3) + " % of body size");
  // Sinks: bodies that stay inside each other through the last fifth of the run by more than
  // 1 % of the smaller body, the bound beyond which a contact depth is clearly wrong
  // (kMarkDepthRel). Resting contact in the reference engines settles below it: on
  // stress/resting_stack Bullet 0.0004 %, ODE 0.013 %, MuJoCo's soft contacts 0.42 %; the
  // custom engine, with no position correction, 2.7 % (4.7 cm; a unit cube's size is its
  // 1.73 m diagonal).
  if (f.rest_penetration > kSinkPenetrationRel)
    sinks.push_back("at rest " + fmt_num(100 * f.rest_penetration, 3) +
                    " % of the smaller body deep in another");
  // Dissipative: with e = 1 and no friction nothing may take energy out. The energy at the end
  // counts, not the lowest: soft contacts (MuJoCo, ODE) store energy in the overlap for a few
  // steps and give it back. 1 % as for growth.
  if (f.restitution >= 1.0 && f.friction == 0.0 && -f.energy_final > kDissipativeEnergyLoss)
    dissipative.push_back("energy lost " + fmt_num(-100 * f.energy_final, 3) + " % with e = 1");
  v.verdict = !unstable.empty()      ? "unstable"
              : !sinks.empty()       ? "sinks"
              : !dissipative.empty() ? "dissipative"
                                     : "stable";
  for (const auto* list : {&unstable, &sinks, &dissipative})
    v.why.insert(v.why.end(), list->begin(), list->end());
  return v;
}

}  // namespace rbx
