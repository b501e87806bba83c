// Contact-law residuals (docs/contact_laws.md): how far each contact point of each step, as a
// backend solved it, is from the laws of rigid contact the scene states. Signorini (no
// penetration, no pulling force, complementarity with Newton's restitution), the Coulomb cone
// and maximum dissipation (a sliding contact's friction opposes its slip at the cone's edge),
// each in its own unit, after Le Lidec et al.'s criteria. Computed from the impulse the library
// reports and the bodies' velocities before and after the step; no library code.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "engine/math.h"

namespace rbx {

/// The five contact laws a residual is measured for, in report order.
enum class Law { Penetration, Pulling, Complementarity, Cone, Dissipation };
/// How many laws.
constexpr int kLaws = 5;
/// Every law, in report order.
constexpr std::array<Law, kLaws> kAllLaws = {Law::Penetration, Law::Pulling, Law::Complementarity,
                                             Law::Cone, Law::Dissipation};
/// "penetration" | "pulling" | "complementarity" | "cone" | "dissipation".
const char* to_string(Law law);
/// The residual's unit: "m" (penetration), "N s" (pulling, cone), "J" (complementarity,
/// dissipation).
const char* law_unit(Law law);

/// Worst and median of one residual over every contact point of every step of a run.
struct LawResidual {
  double worst = 0.0;
  double median = 0.0;  // the histogram's (LawTally): within 1.2 % of the true median
};

/// Friction a body received beyond the Coulomb cone (the cone residual's part of each friction
/// impulse; in Bullet nearly all of it at points left with no normal impulse), and what it did
/// to a body sliding on one surface: the turn about the contact normal and the push along the
/// slide. The turn integrates the yaw rate that friction gives, damped as Coulomb friction damps
/// a sliding box's spin (the loaded points' mu j_n (r . v_hat)^2 / |v| against the inertia about
/// the normal), and held at zero while the body is at rest; the push is the impulse along the
/// slide times the speed over the mass, which moves the stop by push / deceleration
/// (docs/contact_laws.md).
struct ConeExcess {
  int body = 0;            // scene index
  long points = 0;         // contact points with friction beyond the cone, over every step
  double turn_rad = 0.0;   // signed, about the contact normal (out of the surface)
  double push_m2s2 = 0.0;  // signed, along the slide: the stop moves by push / deceleration
};

/// A run's contact-law residuals.
struct ContactLaws {
  bool measured = false;  // the backend reported its contact impulses (false: no residuals)
  long contacts = 0;      // contact points scored, over every step
  std::array<LawResidual, kLaws> residuals{};  // by Law
  std::vector<ConeExcess> cone_excess;         // bodies that received any, in scene order
};

/// What one contact point is scored on. Velocities are of A's material point at the contact
/// relative to B's, before the step (no forces yet) and after it (every impulse and force).
struct LawInputs {
  Vec3 normal = Vec3::UnitZ();   // unit, from B toward A
  double depth = 0.0;            // m, >= 0: penetration at detection
  Vec3 impulse = Vec3::Zero();   // N s, on A over the step
  Vec3 v_before = Vec3::Zero();  // m/s
  Vec3 v_after = Vec3::Zero();   // m/s
  double restitution = 0.0;      // the scene's e
  double friction = 0.0;         // the scene's mu
};

/// The five residuals of one contact point, by Law:
///   penetration     max(0, depth)                                         m
///   pulling         max(0, -j_n)                                          N s
///   complementarity max(0, j_n) |v_n' - max(0, -e v_n)|                   J
///   cone            max(0, |j_t| - mu max(0, j_n))                        N s
///   dissipation     max(0, j_t . v_t' + mu max(0, j_n) |v_t'|)            J
/// with j_n, j_t the impulse's normal and tangential parts, v_n, v_n' the normal velocity
/// before and after, v_t' the tangential velocity after.
std::array<double, kLaws> law_residuals(const LawInputs& in);

/// Worst and median of each residual over many contact points, in constant memory: the worst
/// exactly, the median from a histogram of 100 bins per decade (its geometric centre, so within
/// 1.2 %); values below 1e-30 count as zero.
class LawTally {
 public:
  LawTally();
  /// Adds one contact point's residuals.
  void add(const std::array<double, kLaws>& residuals);
  /// The summary (measured = true).
  ContactLaws summary() const;

 private:
  long count_ = 0;
  std::array<double, kLaws> worst_{};
  std::vector<std::uint32_t> bins_;  // per law: the zero bin, then the decades' bins
};

}  // namespace rbx
