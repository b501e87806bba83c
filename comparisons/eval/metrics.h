// The harness's metric functions: pure functions of body inputs, final states, contact results
// and shapes, so each rule can be tested by hand (tests/comparisons/metrics_test.cpp) without a
// scene or a backend. comparisons/eval/harness.cpp applies them to every backend.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/body.h"
#include "reference/backend.h"

namespace rbx {

/// The median of `v` (the mean of the middle two when even); `v` must not be empty.
double median_of(std::vector<double> v);
/// Quantile q in [0, 1] of sorted values, interpolated linearly between neighbours; 0 for none.
double sorted_quantile(const std::vector<double>& sorted, double q);

/// Reference final velocities of one body; a quantity left empty is not compared.
struct RefState {
  std::optional<Vec3> velocity;          // m/s, centre of mass, world
  std::optional<Vec3> angular_velocity;  // rad/s, world frame
};

/// Velocity error in the kinetic-energy norm: sqrt(sum m|dv|^2 + dw.I.dw) / sqrt(2 E_ref), with
/// I the body's world inertia at its final orientation and E_ref the kinetic energy of the
/// reference velocities. Only the bodies (and quantities) present in `ref` count; static bodies
/// never do. When E_ref is below 1e-12 of `fallback_energy` (a reference at rest), E_ref is
/// `fallback_energy` (the initial kinetic energy).
double ke_norm_error(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& finals,
                     const std::vector<std::optional<RefState>>& ref, double fallback_energy);

/// Kinetic energy (J) of final states, static bodies excluded.
double kinetic_energy(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& s);

/// Total energy (J): kinetic plus gravitational potential -m g.x, static bodies excluded.
double total_energy(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& s,
                    const Vec3& gravity);

/// Kinetic energy (J) the reference velocities give, or nullopt unless `ref` has both the
/// velocity and the angular velocity of every moving body. The rotational part uses each body's
/// inertia at its orientation in `finals` (the backend's; the reference gives no orientation).
std::optional<double> expected_kinetic_energy(const std::vector<RigidBody>& inputs,
                                              const std::vector<BodyFinal>& finals,
                                              const std::vector<std::optional<RefState>>& ref);

/// An energy error and what it was measured against.
struct EnergyError {
  double value = 0.0;   // relative to the energy scale
  std::string against;  // "analytic" | "invariant"
};

/// Energy against what the restitution allows. With an expected final kinetic energy (from a
/// closed form): |KE_final - KE_expected| / scale, against "analytic". Otherwise the invariant
/// rule on the total energy: e = 1 allows no change, |E1 - E0| / scale; e < 1 allows a loss but
/// never a gain, max(E1 - E0, 0) / scale.
EnergyError energy_error(double e0, double e1, double ke_final, std::optional<double> ke_expected,
                         double restitution, double scale);

/// Distance (m) from p to the convex planar polygon `poly` (or segment, or point), in 3-D;
/// infinity for an empty polygon.
double distance_to_region(const Vec3& p, const std::vector<Vec3>& poly);

/// Distance (m) from a reported contact point to the true contact region, the union of the
/// intersection volume and the exact manifold's hull: 0 when p lies inside both bodies (within
/// the engine's point-in-mesh round-off tolerance), else the distance to the manifold polygon.
/// Exact where p is inside both bodies; an upper bound otherwise (the volume may be nearer).
double contact_point_error(const Vec3& p, const RigidBody& a, const RigidBody& b,
                           const std::vector<Vec3>& manifold);

/// Touch agreement: 0 when the result reports a contact exactly when the truth is touching,
/// 1 otherwise (a missed contact or a false one).
double touching_error(const ContactResult& r, bool true_touching);

/// What a stability run measured (relative quantities are fractions, not percent).
struct StabilityFacts {
  bool nonfinite = false;         // a non-finite position or velocity was seen
  bool stopped = false;           // the backend stopped with an error
  std::string stop_message;       // its message
  double energy_growth = 0.0;     // (max E - E0) / scale over the run
  double energy_made_j = 0.0;     // J, > 0: the bodies started still with no energy, and the
                                  // run gave them this much (growth is then relative to it)
  double energy_final = 0.0;      // (E_end - E0) / scale: the signed change at the end
  double restitution = 1.0;       // the scene's e
  double friction = 0.0;          // the scene's Coulomb mu
  bool closed = false;            // no static body and no gravity: momentum is an invariant
  double momentum_drift = 0.0;    // max |p - p0| / p_scale (closed systems)
  double max_penetration = 0.0;   // max exact depth / smaller body size, whole run
  double rest_penetration = 0.0;  // least over the last fifth of the run of each sample's
                                  // deepest overlap / smaller body size (sustained, at rest)
  int tunnelled_pairs = 0;        // pairs that passed through each other
};

/// A stability verdict and the reasons behind it.
struct StabilityVerdict {
  std::string verdict;           // "unstable" | "sinks" | "dissipative" | "stable"
  std::vector<std::string> why;  // every rule that fired, in that order
};

/// Verdict thresholds (fractions): energy growth, dissipation and penetration at rest.
constexpr double kUnstableEnergyGrowth = 0.01;
constexpr double kDissipativeEnergyLoss = 0.01;
constexpr double kSinkPenetrationRel = 0.01;

/// The stability verdict, worst word first:
/// - "unstable": non-finite state, energy gain > 1 % (of the starting energy; where the bodies
///   start still with none, any gain is "energy from nothing"), tunnelling, a stopped run, momentum
///   drift > 1e-6 in a closed system, or penetration > 50 % of the smaller body at any time;
/// - "sinks": penetrating by more than 1 % of the smaller body in every sample of the last fifth
///   of the run (bodies come to rest inside each other);
/// - "dissipative": e = 1 and no friction, yet the run ends with more than 1 % of the energy
///   lost (nothing in the scene may take energy out);
/// - "stable": none of these. `why` lists every rule that fired, so a run can be both.
StabilityVerdict stability_verdict(const StabilityFacts& f);

}  // namespace rbx
