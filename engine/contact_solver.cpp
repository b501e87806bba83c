#include "engine/contact_solver.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace rbx {

namespace {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;

// Per-body data the solver reads: inverse mass and world inverse inertia (zero when static).
struct BodyInverse {
  double inv_mass = 0.0;            // 1/kg
  Mat3 inv_inertia = Mat3::Zero();  // world frame
};

std::vector<BodyInverse> inverses(const std::vector<RigidBody>& bodies) {
  std::vector<BodyInverse> out(bodies.size());
  for (size_t i = 0; i < bodies.size(); ++i)
    if (!bodies[i].is_static) out[i] = {bodies[i].inverse_mass, bodies[i].inverse_inertia_world()};
  return out;
}

// One constraint row set: a point with its normal and tangent directions.
struct Row {
  int a = 0, b = 0, manifold = 0, index = 0;  // bodies, manifold, point within it
  Vec3 point, n, t1, t2, ra, rb;
  double normal_mass_inv = 0.0;  // 1 / (n . K n), K the point's 3x3 inverse effective mass
  Mat2 kt = Mat2::Identity();    // tangent block of K
  double kt_max = 1.0;           // largest eigenvalue of kt
  double target = 0.0;           // m/s, the normal velocity the solve aims at
  double newton_target = 0.0;    // m/s, Newton's -e v_n0 (target = a fraction of it, see below)
  double speed = 0.0;            // m/s, the larger of |v_n0| and |v_rel| at the start
  double jn = 0.0;               // N s, accumulated
  Vec2 jt = Vec2::Zero();        // N s, accumulated, in (t1, t2)
};

// K u: the relative velocity change at the point per unit impulse u (applied +u on A, -u on B).
Vec3 response(const BodyInverse& A, const BodyInverse& B, const Row& r, const Vec3& u) {
  return (A.inv_mass + B.inv_mass) * u + (A.inv_inertia * r.ra.cross(u)).cross(r.ra) +
         (B.inv_inertia * r.rb.cross(u)).cross(r.rb);
}

Vec3 rel_velocity(const RigidBody& a, const RigidBody& b, const Row& r) {
  return (a.velocity + a.angular_velocity.cross(r.ra)) -
         (b.velocity + b.angular_velocity.cross(r.rb));
}

void apply(RigidBody& a, RigidBody& b, const BodyInverse& A, const BodyInverse& B, const Row& r,
           const Vec3& p) {
  a.velocity += A.inv_mass * p;
  a.angular_velocity += A.inv_inertia * r.ra.cross(p);
  b.velocity -= B.inv_mass * p;
  b.angular_velocity -= B.inv_inertia * r.rb.cross(p);
}

// A unit vector perpendicular to n.
Vec3 perpendicular(const Vec3& n) {
  const Vec3 t = std::abs(n.x()) < 0.57735 ? Vec3::UnitX().cross(n) : Vec3::UnitY().cross(n);
  return t.normalized();
}

}  // namespace

std::vector<std::vector<double>> normal_velocities(const std::vector<RigidBody>& bodies,
                                                   const std::vector<PairManifold>& manifolds) {
  std::vector<std::vector<double>> out;
  out.reserve(manifolds.size());
  for (const PairManifold& pm : manifolds) {
    const RigidBody &a = bodies[pm.a], &b = bodies[pm.b];
    std::vector<double> v;
    for (const ManifoldPoint& p : pm.manifold.points) {
      const Vec3 ra = p.point - a.position, rb = p.point - b.position;
      const Vec3 vrel =
          (a.velocity + a.angular_velocity.cross(ra)) - (b.velocity + b.angular_velocity.cross(rb));
      v.push_back(vrel.dot(pm.manifold.normal));
    }
    out.push_back(std::move(v));
  }
  return out;
}

namespace {

/// Solves one island's rows to convergence (velocities of `bodies` and the rows' accumulated
/// impulses in place): staggered projections, and the energy guard on restitution.
void solve_island(std::vector<RigidBody>& bodies, const std::vector<BodyInverse>& inv,
                  std::vector<Row>& rows, const ContactSolverSettings& settings) {
  double speed_scale = 0.0;  // m/s, the largest speed in the problem
  for (const Row& r : rows) speed_scale = std::max(speed_scale, r.speed);
  // Staggered projections (Kaufman, Sueda, James & Pai 2008): the normal impulses with the
  // friction impulses held, then the friction impulses inside the cones those normal impulses
  // give, repeated until neither moves. Each stage is a convex problem that projected
  // Gauss-Seidel solves to convergence; interleaving both in one sweep instead cycled at 1e-8 m/s
  // on a five-cube stack (the cone radius moving under the friction rows).
  // Converged: a sweep that changes no point's velocity by more than 1e-14 of the problem's
  // speed is a fixed point to round-off (the seed's closed forms are checked to 1e-9; 1e-14
  // leaves five digits). 10000 sweeps and 100 stages bound pathological graphs; a chain of n
  // bodies converges in O(n^2) sweeps.
  const double converged = 1e-14 * std::max(speed_scale, 1e-300);
  const double mu = settings.friction;
  auto normal_sweep = [&]() {
    double change = 0.0;  // m/s, largest velocity change at a point in this sweep
    for (Row& r : rows) {
      RigidBody &a = bodies[r.a], &b = bodies[r.b];
      const BodyInverse &A = inv[r.a], &B = inv[r.b];
      // Normal: accumulated impulse clamped at 0 (complementarity).
      const double vn = rel_velocity(a, b, r).dot(r.n);
      const double jn_new = std::max(r.jn + (r.target - vn) * r.normal_mass_inv, 0.0);
      const double djn = jn_new - r.jn;
      if (djn != 0.0) {
        apply(a, b, A, B, r, djn * r.n);
        r.jn = jn_new;
        change = std::max(change, std::abs(djn) / r.normal_mass_inv);
      }
    }
    return change;
  };
  auto friction_sweep = [&]() {
    double change = 0.0;
    for (Row& r : rows) {
      RigidBody &a = bodies[r.a], &b = bodies[r.b];
      const BodyInverse &A = inv[r.a], &B = inv[r.b];
      // Friction: a projected gradient step on the accumulated tangent impulse, with the step
      // 1/k_max (k_max the largest eigenvalue of the tangent block K_t), projected onto the
      // disc |j_t| <= mu j_n: the exact Coulomb cone, not a pyramid. With the scalar step the
      // fixed point is Coulomb's law itself: sticking (v_t = 0) inside the disc, or sliding
      // with j_t = -mu j_n v_t/|v_t|, exactly against the slip (a 2x2 solve K_t^-1 v_t would
      // leave j_t along K_t^-1 v_t, off the slip when K_t is anisotropic). Against the slip
      // it removes energy: dE = P.v' - P^T K P / 2 <= 0. The step 1/k_max makes each update
      // descend the kinetic energy of the problem (projected gradient with step 1/L).
      const Vec3 vrel = rel_velocity(a, b, r);
      const Vec2 vt(vrel.dot(r.t1), vrel.dot(r.t2));
      Vec2 jt_new = r.jt - vt / r.kt_max;
      const double limit = mu * r.jn;
      if (jt_new.norm() > limit) jt_new *= limit / jt_new.norm();
      const Vec2 d = jt_new - r.jt;
      if (d.squaredNorm() == 0.0) continue;
      apply(a, b, A, B, r, d.x() * r.t1 + d.y() * r.t2);
      r.jt = jt_new;
      change = std::max(change, (r.kt * d).norm());
    }
    return change;
  };
  // Sweeps of one stage until converged; returns how many changed something.
  auto stage = [&](auto&& sweep_fn) {
    int moving = 0;
    for (int sweep = 0; sweep < 10000; ++sweep) {
      if (sweep_fn() <= converged) break;
      ++moving;
    }
    return moving;
  };
  auto solve = [&]() {
    for (int round = 0; round < 100 && !rows.empty(); ++round) {
      const int normal_moved = stage(normal_sweep);
      if (!(mu > 0.0)) break;
      const int friction_moved = stage(friction_sweep);
      if (round > 0 && normal_moved == 0 && friction_moved == 0) break;
      if (round == 0 && friction_moved == 0) break;
    }
  };
  // Kinetic energy of the bodies in the problem (J).
  std::vector<int> involved;
  for (const Row& r : rows)
    for (int i : {r.a, r.b})
      if (std::find(involved.begin(), involved.end(), i) == involved.end()) involved.push_back(i);
  auto kinetic = [&]() {
    double k = 0.0;
    for (int i : involved) k += bodies[i].kinetic_energy();
    return k;
  };
  std::vector<std::pair<Vec3, Vec3>> start;
  for (int i : involved) start.emplace_back(bodies[i].velocity, bodies[i].angular_velocity);
  const double kinetic_before = kinetic();
  solve();
  // Departure from a plain Newton law: with friction, Newton's restitution on the normal
  // velocity can create energy (Kane & Levinson's paradox: the friction impulse turns the body
  // so the normal velocity it must reverse grows). Where the solve ended with more kinetic
  // energy than it started with (beyond 1e-12 relative: round-off of an elastic frictionless
  // solve), the restitution targets are scaled down, by bisection, to the largest fraction that
  // adds none; at e = 0 the solve only dissipates (j_n v_n' = 0, j_t . v_t' <= 0), so a fraction
  // always exists. Frictionless one-point impacts never get here (they keep the energy e^2).
  const double allowed = kinetic_before * (1.0 + 1e-12) + 1e-300;
  if (kinetic() > allowed && settings.restitution > 0.0) {
    auto restart = [&](double fraction) {
      for (size_t k = 0; k < involved.size(); ++k) {
        bodies[involved[k]].velocity = start[k].first;
        bodies[involved[k]].angular_velocity = start[k].second;
      }
      for (Row& r : rows) {
        r.jn = 0.0;
        r.jt.setZero();
        r.target = fraction * r.newton_target;
      }
      solve();
    };
    double lo = 0.0, hi = 1.0;  // fractions: lo adds no energy, hi does
    for (int it = 0; it < 30; ++it) {
      const double mid = 0.5 * (lo + hi);
      restart(mid);
      (kinetic() > allowed ? hi : lo) = mid;
    }
    restart(lo);
  }
}

}  // namespace

std::vector<SolvedPoint> solve_contact_velocities(std::vector<RigidBody>& bodies,
                                                  const std::vector<PairManifold>& manifolds,
                                                  const std::vector<std::vector<double>>& approach,
                                                  const ContactSolverSettings& settings) {
  const std::vector<BodyInverse> inv = inverses(bodies);
  std::vector<Row> rows;
  for (size_t m = 0; m < manifolds.size(); ++m) {
    const PairManifold& pm = manifolds[m];
    const BodyInverse &A = inv[pm.a], &B = inv[pm.b];
    for (size_t k = 0; k < pm.manifold.points.size(); ++k) {
      Row r;
      r.a = pm.a;
      r.b = pm.b;
      r.manifold = static_cast<int>(m);
      r.index = static_cast<int>(k);
      r.point = pm.manifold.points[k].point;
      r.n = pm.manifold.normal;
      r.t1 = perpendicular(r.n);
      r.t2 = r.n.cross(r.t1);
      r.ra = r.point - bodies[pm.a].position;
      r.rb = r.point - bodies[pm.b].position;
      const double kn = r.n.dot(response(A, B, r, r.n));
      if (!(kn > 0.0)) continue;  // both static
      r.normal_mass_inv = 1.0 / kn;
      const Vec3 k1 = response(A, B, r, r.t1), k2 = response(A, B, r, r.t2);
      r.kt << r.t1.dot(k1), r.t1.dot(k2), r.t2.dot(k1), r.t2.dot(k2);
      const double half_trace = 0.5 * (r.kt(0, 0) + r.kt(1, 1));
      const double half_diff = 0.5 * (r.kt(0, 0) - r.kt(1, 1));
      r.kt_max = half_trace + std::hypot(half_diff, 0.5 * (r.kt(0, 1) + r.kt(1, 0)));
      // Newton's law on the normal velocity: a collision (approach faster than rest_speed)
      // leaves at -e times its approach; a resting contact is only stopped.
      const double vn0 = approach[m][k];
      r.newton_target = vn0 < -settings.rest_speed ? -settings.restitution * vn0 : 0.0;
      r.target = r.newton_target;
      r.speed = std::max(std::abs(vn0), rel_velocity(bodies[r.a], bodies[r.b], r).norm());
      rows.push_back(r);
    }
  }

  // Islands: rows that share a moving body (static bodies do not join them) are one problem;
  // separate islands cannot affect each other, so each is solved to its own convergence
  // instead of sweeping every row until the slowest island converges (many_1000: ~1,700
  // sweeps of every row per step for one face contact).
  std::vector<int> parent(bodies.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const Row& r : rows)
    if (!bodies[r.a].is_static && !bodies[r.b].is_static) parent[root(r.a)] = root(r.b);
  auto island_of = [&](const Row& r) { return root(bodies[r.a].is_static ? r.b : r.a); };
  std::vector<int> order;  // island roots in the order of their first row (deterministic)
  std::vector<std::vector<size_t>> members(bodies.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    const int isl = island_of(rows[k]);
    if (members[isl].empty()) order.push_back(isl);
    members[isl].push_back(k);
  }
  for (int isl : order) {
    std::vector<Row> island;
    island.reserve(members[isl].size());
    for (size_t k : members[isl]) island.push_back(rows[k]);
    solve_island(bodies, inv, island, settings);
    for (size_t k = 0; k < island.size(); ++k) rows[members[isl][k]] = island[k];
  }

  std::vector<SolvedPoint> out;
  out.reserve(rows.size());
  for (const Row& r : rows) {
    out.push_back({r.manifold, r.point, r.jn, r.jt.x() * r.t1 + r.jt.y() * r.t2,
                   -approach[r.manifold][r.index]});
  }
  return out;
}

void project_contact_positions(std::vector<RigidBody>& bodies,
                               const std::vector<PairManifold>& manifolds) {
  // Box2D's values (b2_baumgarte = 0.2 of the error per iteration) with four iterations remove
  // 1 - 0.8^4 = 59 % of a penetration per step, fast enough that a landing at v leaves at most
  // ~v dt, not so fast that a deep start is thrown apart in one step. The slop, 1e-4 of the
  // smaller body's size, keeps touching contacts touching (the detector sees them next step)
  // and is 10x under the 0.1 % of a body the issue allows at rest.
  // Moving positions with the velocities held does not keep the angular momentum about the
  // origin (r x m v changes with r): measured on many_1000, the drift of 1.2e-7 (relative) is
  // this projection's (without it, 1e-15); Bullet's positional correction drifts 1.1e-6 there.
  constexpr double kBaumgarte = 0.2;
  constexpr int kIterations = 4;
  const std::vector<BodyInverse> inv = inverses(bodies);
  for (int it = 0; it < kIterations; ++it)
    for (const PairManifold& pm : manifolds) {
      RigidBody &a = bodies[pm.a], &b = bodies[pm.b];
      const BodyInverse &A = inv[pm.a], &B = inv[pm.b];
      const double size_a = (a.shape->bounds().max - a.shape->bounds().min).norm();
      const double size_b = (b.shape->bounds().max - b.shape->bounds().min).norm();
      const double slop = 1e-4 * std::min(size_a, size_b);
      const Vec3& n = pm.manifold.normal;
      for (const ManifoldPoint& p : pm.manifold.points) {
        // The point's anchors on A and B moved with the bodies since detection.
        const Vec3 pa = a.pose().apply(pm.pose_a.inverse_apply(p.point));
        const Vec3 pb = b.pose().apply(pm.pose_b.inverse_apply(p.point));
        const double depth = p.depth - (pa - pb).dot(n);
        const double c = kBaumgarte * (depth - slop);
        if (!(c > 0.0)) continue;
        const Vec3 ra = pa - a.position, rb = pb - b.position;
        const Vec3 ran = ra.cross(n), rbn = rb.cross(n);
        const double k =
            A.inv_mass + B.inv_mass + ran.dot(A.inv_inertia * ran) + rbn.dot(B.inv_inertia * rbn);
        if (!(k > 0.0)) continue;
        const Vec3 P = (c / k) * n;
        auto turn = [](RigidBody& body, const Vec3& angle) {
          const double t = angle.norm();
          if (t > 0.0)
            body.orientation =
                (Quat(Eigen::AngleAxisd(t, angle / t)) * body.orientation).normalized();
        };
        if (!a.is_static) {
          a.position += A.inv_mass * P;
          turn(a, A.inv_inertia * ra.cross(P));
        }
        if (!b.is_static) {
          b.position -= B.inv_mass * P;
          turn(b, -(B.inv_inertia * rb.cross(P)));
        }
      }
    }
}

}  // namespace rbx
