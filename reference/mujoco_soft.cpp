// MuJoCo's soft contact as rbx sets it: the stiffness for a contact duration in steps and the
// damping ratio that returns a scene's restitution (reference/mujoco_soft.h). No MuJoCo call: the
// map integrates the contact as mj_step does.
#include "reference/mujoco_soft.h"

#include <algorithm>
#include <cmath>

namespace rbx {

// Stiffness (1/s^2, per unit effective mass) for a contact lasting `steps` steps when
// undamped: half period pi / sqrt(k) = steps * dt.
double contact_stiffness(double dt, double steps) {
  const double w = M_PI / (steps * dt);
  return w * w;
}

// Restitution of one soft contact as MuJoCo integrates it, in contact space and in units where
// dt = 1 and the approach speed is 1 (the map is scale-free: see restitution_damping_ratio).
// `entry_phase` in [0, 1] is the penetration at the first step that sees the contact, in units
// of (approach speed * dt): contacts are detected at step starts, so the body is already that
// deep. Semi-implicit Euler with aref explicit in x and v, as mj_step does:
//   a = max(0, -b x' - k x),  x' += a,  x += x'   (x = dist, < 0 inside)
// until the body is out (x >= 0); the returned separation speed is e.
double soft_contact_restitution(double zeta, double entry_phase, double steps) {
  const double w = M_PI / steps;  // sqrt(k0) * dt
  const double k = w * w, b = 2.0 * zeta * w;
  double v = -1.0, x = -entry_phase;
  for (int it = 0; it < 1000000 && x < 0.0; ++it) {
    v += std::max(0.0, -b * v - k * x);  // the contact pushes, never pulls
    x += v;
  }
  return v;
}

// Damping ratio zeta that makes MuJoCo's soft contact return restitution e.
//
// Model. With a direct solref (-k0, -b0) and a constant impedance d, MuJoCo uses
// K = k0/d^2, B = b0/d and aref = -B v - K d x (x = dist, < 0 inside, v its rate); for one
// frictionless contact the solver's constraint acceleration is
// a = a0 + A/(A+R) (aref - a0), R = (1-d)/d * A~ (A~ its diagonal approximation), i.e. a = aref
// to O(1-d) = 1e-4. So the penetration delta = -x obeys delta'' = -b0 delta' - k0 delta: a
// spring-dashpot per unit effective mass (the effective mass 1/A drops out, so the map holds
// for any masses and lever arms). Assumptions: one contact point, normal and lever arm fixed
// during the impact, no gravity or other force during it, d = 0.9999.
//
// Continuous map (the derivation). The constraint cannot pull (force >= 0), so contact ends
// when k0 delta + b0 delta' reaches zero (delta'' = 0), before delta returns to zero; the
// classic e = exp(-zeta pi / sqrt(1 - zeta^2)) assumes the dashpot may pull until delta = 0
// and overestimates the dissipation (e = 0.5 needs zeta = 0.215 classic, 0.255 unilateral).
// With zeta = b0 / (2 sqrt(k0)), delta(0) = 0, delta'(0) = v0:
//   zeta < 1: e = exp(-zeta/sqrt(1-zeta^2) * (pi - 2 asin zeta))
//             (delta'' = 0 at w_d t = pi - 2 asin zeta, where delta' = -v0 exp(-b0 t / 2))
//   zeta = 1: e = exp(-2)
//   zeta > 1: e = ((zeta - s)/(zeta + s))^(zeta/s), s = sqrt(zeta^2 - 1)
//
// Discrete correction (what we invert). At 25 steps per contact (`steps`) the explicit
// damping factor (1 - b0 dt) per step, against exp(-b0 dt), lowers e by a few percent (e = 0.1
// came out 0.072 in MuJoCo with the continuous map, exactly as the recursion predicts). So we
// invert soft_contact_restitution() at the mean entry phase 1/2 by bisection (e decreases
// monotonically in zeta). The entry phase itself is unknown in advance: over phases 0..1 the
// returned e lies between 0.485 and 0.517 for a target of 0.5. zeta is capped where b0 dt = 1
// (more explicit damping would overshoot); e below what the cap reaches is not representable
// and gets the cap (the result's message says so).
double restitution_damping_ratio(double e, double steps) {
  const double zeta_max = steps / (2.0 * M_PI);  // b0 dt = 2 zeta pi / steps = 1
  constexpr double kEntryPhase = 0.5;
  if (e >= 1.0) return 0.0;
  if (e <= soft_contact_restitution(zeta_max, kEntryPhase, steps)) return zeta_max;
  double lo = 0.0, hi = zeta_max;
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (soft_contact_restitution(mid, kEntryPhase, steps) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace rbx
