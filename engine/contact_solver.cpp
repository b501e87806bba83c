#include "engine/contact_solver.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include "engine/dense_solve.h"

namespace rbx {

namespace {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;

// Per-body data the solver reads: inverse mass and world inverse inertia (zero when static).
struct BodyInverse {
  double inv_mass = 0.0;            // 1/kg
  Mat3 inv_inertia = Mat3::Zero();  // world frame
};

// Each body's inverse mass and world-frame inverse inertia, for the bodies the manifolds name
// (the others are never read): one world-frame inertia per body in contact, and storage for
// those alone (a crowd's bodies are mostly out of contact). A static body's are zero.
class Inverses {
 public:
  Inverses(const std::vector<RigidBody>& bodies, const std::vector<PairManifold>& manifolds)
      : slot_(bodies.size(), -1) {
    for (const PairManifold& pm : manifolds)
      for (int i : {pm.a, pm.b}) {
        if (slot_[static_cast<size_t>(i)] >= 0) continue;
        slot_[static_cast<size_t>(i)] = static_cast<int>(of_.size());
        const RigidBody& b = bodies[static_cast<size_t>(i)];
        of_.push_back(b.is_static ? BodyInverse{}
                                  : BodyInverse{b.inverse_mass, b.inverse_inertia_world()});
      }
  }
  const BodyInverse& operator[](int i) const {
    return of_[static_cast<size_t>(slot_[static_cast<size_t>(i)])];
  }

 private:
  std::vector<int> slot_;  // per body: its place in of_, -1 when not named
  std::vector<BodyInverse> of_;
};

// One constraint row set: a point with its normal and tangent directions.
struct Row {
  int a = 0, b = 0, manifold = 0, index = 0;  // bodies, manifold, point within it
  Vec3 point, n, t1, t2, ra, rb;
  double normal_mass_inv = 0.0;  // 1 / (n . K n), K the point's 3x3 inverse effective mass
  Mat2 kt = Mat2::Identity();    // tangent block of K
  double kt_max = 1.0;           // largest eigenvalue of kt
  double target = 0.0;           // m/s, the normal velocity the solve aims at
  double newton_target = 0.0;    // m/s, Newton's -e v_n0 (target = a fraction of it, see below)
  double speed = 0.0;            // m/s, the larger of |v_n0| and v_rel's terms at the start
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

// ---------------------------------------------------------------------------------------------
// Active sets (small islands). Outline of solve_active_set:
//   build K and b                                  (ActiveSet constructor)
//   repeat up to 20 rounds:
//     solve the guess                              (solve_guess)
//     turn the sliding directions                  (settle_slip_directions)
//     no exact answer: drop an assumption, or refuse   (drop_assumption)
//     guess broken: correct it; else apply the answer  (correct_guess, apply_answer)

// A point's guess: pressed and sticking, pressed and sliding, or separating.
enum class Mode { Separate, Stick, Slide };

// One island's problem for the active-set solve: K, b, the guess and its answer.
struct ActiveSet {
  ActiveSet(std::vector<RigidBody>& bodies_in, const Inverses& inv_in, std::vector<Row>& rows_in,
            double mu_in, double tolerance_in);

  // The row's direction e: 0 the normal, 1 and 2 the tangents.
  static const Vec3& direction(const Row& r, int k) {
    return k == 0 ? r.n : (k == 1 ? r.t1 : r.t2);
  }
  void build_system();
  double solve_guess(Eigen::Index& worst);
  Eigen::VectorXd crossing(const std::vector<size_t>& sliding) const;
  double settle_slip_directions(double residual, Eigen::Index& worst);
  bool drop_assumption(Eigen::Index worst);
  bool correct_guess();
  void apply_answer();

  std::vector<RigidBody>& bodies;
  const Inverses& inv;
  std::vector<Row>& rows;
  const double mu, base_tolerance;
  double tolerance;         // m/s: base_tolerance, or the last guess's round-off if larger
  const int per;            // unknowns per row: 3 with friction (n, t1, t2), else 1
  const size_t m;           // rows
  const Eigen::Index size;  // per * m
  Eigen::MatrixXd K;
  Eigen::VectorXd b;
  std::vector<Mode> mode;
  std::vector<Vec2> slip;  // sliding points: unit slip direction in (t1, t2)
  Eigen::VectorXd x, w;    // the last guess's impulses and K x - b
};

ActiveSet::ActiveSet(std::vector<RigidBody>& bodies_in, const Inverses& inv_in,
                     std::vector<Row>& rows_in, double mu_in, double tolerance_in)
    : bodies(bodies_in),
      inv(inv_in),
      rows(rows_in),
      mu(mu_in),
      base_tolerance(tolerance_in),
      tolerance(tolerance_in),
      per(mu_in > 0.0 ? 3 : 1),
      m(rows_in.size()),
      size(static_cast<Eigen::Index>(per * m)),
      K(size, size),
      b(size),
      mode(m, Mode::Stick),
      slip(m, Vec2::Zero()),
      x(size),
      w(size) {
  build_system();
}

// K's column (j, e): every row's relative velocity change for a unit impulse along row j's
// direction e (on A, and its opposite on B); b: the change each row needs (target - v).
void ActiveSet::build_system() {
  for (size_t j = 0; j < m; ++j)
    for (int e = 0; e < per; ++e) {
      const Row& rj = rows[j];
      const Vec3& u = direction(rj, e);
      const Vec3 dva = inv[rj.a].inv_mass * u, dwa = inv[rj.a].inv_inertia * rj.ra.cross(u);
      const Vec3 dvb = -inv[rj.b].inv_mass * u, dwb = -(inv[rj.b].inv_inertia * rj.rb.cross(u));
      for (size_t i = 0; i < m; ++i) {
        const Row& ri = rows[i];
        Vec3 dv = Vec3::Zero();
        for (const auto& [body, lin, ang] :
             {std::tuple{rj.a, dva, dwa}, std::tuple{rj.b, dvb, dwb}}) {
          if (ri.a == body) dv += lin + ang.cross(ri.ra);
          if (ri.b == body) dv -= lin + ang.cross(ri.rb);
        }
        for (int k = 0; k < per; ++k) K(per * i + k, per * j + e) = direction(ri, k).dot(dv);
      }
    }
  for (size_t i = 0; i < m; ++i) {
    const Vec3 v = rel_velocity(bodies[rows[i].a], bodies[rows[i].b], rows[i]);
    b(per * i) = rows[i].target - v.dot(rows[i].n);
    for (int k = 1; k < per; ++k) b(per * i + k) = -v.dot(direction(rows[i], k));
  }
}

// One guess's linear system: unknowns j_n of pressed points and j_t of sticking ones;
// equations the normal of pressed points and the tangents of sticking ones. Sets x (every
// row's impulses, (n, t1, t2) per row) and w = K x - b (normal: v_n - target; tangents: v_t);
// returns the residual (m/s) and the equation it is largest at (-1 if none).
double ActiveSet::solve_guess(Eigen::Index& worst) {
  std::vector<Eigen::Index> equations;
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(size, size);
  Eigen::Index unknowns = 0;
  for (size_t i = 0; i < m; ++i) {
    const Eigen::Index r0 = per * static_cast<Eigen::Index>(i);
    if (mode[i] == Mode::Separate) continue;
    equations.push_back(r0);
    E(r0, unknowns) = 1.0;
    if (mode[i] == Mode::Slide) {
      E(r0 + 1, unknowns) = -mu * slip[i].x();
      E(r0 + 2, unknowns) = -mu * slip[i].y();
    }
    ++unknowns;
    if (mode[i] == Mode::Stick && per == 3) {
      equations.insert(equations.end(), {r0 + 1, r0 + 2});
      E(r0 + 1, unknowns++) = 1.0;
      E(r0 + 2, unknowns++) = 1.0;
    }
  }
  worst = -1;
  x.setZero();
  if (equations.empty()) {
    tolerance = base_tolerance;
    w = -b;
    return 0.0;
  }
  const Eigen::Index count = static_cast<Eigen::Index>(equations.size());
  const Eigen::MatrixXd KE = K * E.leftCols(unknowns);
  Eigen::MatrixXd A(count, unknowns);
  Eigen::VectorXd rhs(count);
  for (Eigen::Index q = 0; q < count; ++q) {
    A.row(q) = KE.row(equations[q]);
    rhs(q) = b(equations[q]);
  }
  const Eigen::VectorXd y = least_norm_solve_refined(A, rhs);
  x = E.leftCols(unknowns) * y;
  w = K * x - b;
  // Each equation K x - b sums `size` terms K_qj x_j and b_q, which cancel at a resting stack
  // (the weight above a box pressing down, the floor pressing up); the rounding bound of such a
  // sum, size * eps * (sum |K_qj x_j| + |b_q|) (Higham's gamma_n), is the finest test the answer
  // can pass.
  tolerance =
      std::max(base_tolerance, static_cast<double>(size) * std::numeric_limits<double>::epsilon() *
                                   (K.cwiseAbs() * x.cwiseAbs() + b.cwiseAbs()).maxCoeff());
  Eigen::Index q = 0;
  const double residual = (A * y - rhs).cwiseAbs().maxCoeff(&q);
  worst = equations[q];
  return residual;
}

// Slip off its assumed direction at each sliding point (m/s): the component of v_t across it.
Eigen::VectorXd ActiveSet::crossing(const std::vector<size_t>& sliding) const {
  Eigen::VectorXd g(static_cast<Eigen::Index>(sliding.size()));
  for (size_t k = 0; k < sliding.size(); ++k) {
    const Eigen::Index r0 = per * static_cast<Eigen::Index>(sliding[k]);
    g(static_cast<Eigen::Index>(k)) =
        slip[sliding[k]].x() * w(r0 + 2) - slip[sliding[k]].y() * w(r0 + 1);
  }
  return g;
}

// Turns the unit vector s by `angle` (rad).
void turn(Vec2& s, double angle) {
  s = Vec2(std::cos(angle) * s.x() - std::sin(angle) * s.y(),
           std::sin(angle) * s.x() + std::cos(angle) * s.y());
}

// The sliding points' directions: Newton on their angles until each slips along its own (the
// slip's crossing component zero), the Jacobian by finite differences (one solve per sliding
// point; 1e-7 rad, where the difference's round-off and curvature errors balance). Takes and
// returns the guess's residual (and its worst equation), re-solved after each turn.
double ActiveSet::settle_slip_directions(double residual, Eigen::Index& worst) {
  std::vector<size_t> sliding;
  for (size_t i = 0; i < m; ++i)
    if (mode[i] == Mode::Slide) sliding.push_back(i);
  for (int it = 0; it < 12 && !sliding.empty() && residual <= tolerance; ++it) {
    const Eigen::VectorXd g = crossing(sliding);
    if (g.cwiseAbs().maxCoeff() <= tolerance) break;
    const Eigen::Index ns = g.size();
    Eigen::MatrixXd J(ns, ns);
    constexpr double kStep = 1e-7;
    for (Eigen::Index k = 0; k < ns; ++k) {
      turn(slip[sliding[k]], kStep);
      Eigen::Index unused = -1;
      solve_guess(unused);
      J.col(k) = (crossing(sliding) - g) / kStep;
      turn(slip[sliding[k]], -kStep);
    }
    Eigen::VectorXd step = -pivoted_qr_solve(J, g);
    const double largest = step.cwiseAbs().maxCoeff();
    if (!(largest < 1e300)) break;
    if (largest > 0.5) step *= 0.5 / largest;  // at most half a radian a step
    for (Eigen::Index k = 0; k < ns; ++k) turn(slip[sliding[k]], step(k));
    residual = solve_guess(worst);
  }
  return residual;
}

// No exact answer (targets the bodies cannot all meet): the least-squares answer's worst
// equation says which assumption to drop. A normal left above its target separates; a sticking
// point left slipping slides that way; anything else is refused (returns false).
bool ActiveSet::drop_assumption(Eigen::Index worst) {
  const Eigen::Index i = worst / per;
  if (worst % per == 0 && w(worst) > tolerance) {
    mode[i] = Mode::Separate;
  } else if (worst % per != 0 && mode[i] == Mode::Stick) {
    const Vec2 vt(w(per * i + 1), w(per * i + 2));
    if (!(vt.norm() > 0.0)) return false;
    mode[i] = Mode::Slide;
    slip[i] = vt.normalized();
  } else {
    return false;
  }
  return true;
}

// Corrects the guess where the answer breaks it: a sticking point whose impulse pulls or leaves
// its cone slides against that impulse; a sliding one that pulls separates, one whose slip
// reversed sticks; a separating one that goes below its target is pressed, sliding if it slips.
// Returns whether anything changed.
bool ActiveSet::correct_guess() {
  bool changed = false;
  for (size_t i = 0; i < m; ++i) {
    const Eigen::Index r0 = per * static_cast<Eigen::Index>(i);
    const double jn = x(r0);
    const Vec2 jt = per == 3 ? Vec2(x(r0 + 1), x(r0 + 2)) : Vec2::Zero();
    const Vec2 vt = per == 3 ? Vec2(w(r0 + 1), w(r0 + 2)) : Vec2::Zero();
    const Mode was = mode[i];
    if (mode[i] == Mode::Separate) {
      if (w(r0) < -tolerance) {
        mode[i] = vt.norm() > tolerance ? Mode::Slide : Mode::Stick;
        if (mode[i] == Mode::Slide) slip[i] = vt.normalized();
      }
    } else if (mode[i] == Mode::Stick) {
      if (jn < 0.0 || jt.norm() > mu * jn * (1.0 + 1e-12)) {
        mode[i] = jt.norm() > 0.0 ? Mode::Slide : Mode::Separate;
        if (mode[i] == Mode::Slide) slip[i] = -jt.normalized();
      }
    } else if (jn < 0.0) {
      mode[i] = Mode::Separate;
    } else if (vt.norm() <= tolerance) {
      // Stopped with the friction at the cone's edge: sticking at the most the cone allows, a
      // valid answer (v_t = 0, |j_t| = mu j_n); calling it sticking instead made the guess cycle
      // (the least-norm sticking answer leaves the cone, which slides it again).
    } else if (!(vt.dot(slip[i]) > tolerance)) {
      mode[i] = Mode::Stick;  // stopped or reversed: try it sticking
    } else if (std::abs(slip[i].x() * vt.y() - slip[i].y() * vt.x()) > tolerance) {
      slip[i] = vt.normalized();  // Newton did not settle it: restart from the slip itself
      changed = true;
    }
    changed = changed || mode[i] != was;
  }
  return changed;
}

// The settled answer: impulses on the rows, velocities on the bodies.
void ActiveSet::apply_answer() {
  for (size_t i = 0; i < m; ++i) {
    Row& r = rows[i];
    r.jn = x(per * i);
    r.jt = per == 3 ? Vec2(x(per * i + 1), x(per * i + 2)) : Vec2::Zero();
    apply(bodies[r.a], bodies[r.b], inv[r.a], inv[r.b], r,
          r.jn * r.n + r.jt.x() * r.t1 + r.jt.y() * r.t2);
  }
}

/// The island's problem solved by active sets: each point is guessed pressed and sticking,
/// pressed and sliding in a given direction, or separating; for a guess the problem is one
/// linear system (pressed: normal velocity at its target; sticking: tangent velocity zero;
/// sliding: the friction impulse -mu j_n along the slip), solved for its least-norm answer;
/// the guess is then corrected where the answer breaks its own assumption (a pulling normal
/// impulse separates, a separating point below its target is pressed, a sticking impulse
/// outside its cone slides against it, a sliding point that stopped or turned sticks or takes
/// its slip's direction) until none changes. The answer then meets every condition of the
/// contact problem to `tolerance` (m/s): complementarity on every normal, Coulomb's disc and
/// maximal dissipation on every tangent; it is applied (impulses on the rows, velocities on
/// the bodies). A guess with no exact answer (targets no motion of the bodies meets: a face
/// with some points bouncing and some resting) drops the assumption its least-squares answer
/// breaks most. Returns false, touching nothing, when the guesses do not settle in 20 rounds
/// or no assumption can be dropped; the projections then solve it.
bool solve_active_set(std::vector<RigidBody>& bodies, const Inverses& inv, std::vector<Row>& rows,
                      double mu, double tolerance) {
  constexpr int kMaxRounds = 20;
  if (rows.empty()) return false;
  ActiveSet problem(bodies, inv, rows, mu, tolerance);
  for (int round = 0; round < kMaxRounds; ++round) {
    Eigen::Index worst = -1;
    double residual = problem.solve_guess(worst);
    residual = problem.settle_slip_directions(residual, worst);
    if (!(residual <= problem.tolerance)) {
      if (!problem.drop_assumption(worst)) return false;
      continue;
    }
    if (problem.correct_guess()) continue;
    problem.apply_answer();
    return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// Staggered projections (every island). Outline of solve_island:
//   remember the start                 (IslandSolver constructor)
//   active sets for small islands, then rounds of two stages until neither moves    (solve)
//     a stage: projected Gauss-Seidel iterations to convergence, steady drifts taken at once
//              (stage; normal_iteration or friction_iteration)
//   energy guard: restitution scaled down by bisection where the solve added energy
//              (guard_energy)

// One island's staggered projections, its convergence test and its energy guard.
struct IslandSolver {
  IslandSolver(std::vector<RigidBody>& bodies_in, const Inverses& inv_in, std::vector<Row>& rows_in,
               const ContactSolverSettings& settings_in, SolverWork& work_in);

  double normal_iteration();
  double friction_iteration();
  void rescale();
  void unknowns(bool friction, std::vector<double>& out) const;
  double iterations_to_bound(bool friction, const std::vector<double>& d) const;
  void take_drift(bool friction, const std::vector<double>& d, double count);
  int stage(bool friction);
  void solve();
  double kinetic() const;
  void restart(double fraction);
  void guard_energy();

  std::vector<RigidBody>& bodies;
  const Inverses& inv;
  std::vector<Row>& rows;
  const ContactSolverSettings& settings;
  SolverWork& work;
  const double mu;
  double speed_scale = 0.0;                     // m/s, the largest speed in the problem
  double converged = 0.0;                       // m/s, the convergence test's threshold
  std::vector<double> before, after, d, drift;  // the stages' buffers, kept across iterations
  std::vector<int> involved;                    // the bodies in the problem
  std::vector<std::pair<Vec3, Vec3>> start;     // their velocities before the solve
  double kinetic_before = 0.0;                  // J, their kinetic energy before the solve
  long budget_left = 0;  // iterations this solve may still take (WorldSettings::iteration_budget)
};

IslandSolver::IslandSolver(std::vector<RigidBody>& bodies_in, const Inverses& inv_in,
                           std::vector<Row>& rows_in, const ContactSolverSettings& settings_in,
                           SolverWork& work_in)
    : bodies(bodies_in),
      inv(inv_in),
      rows(rows_in),
      settings(settings_in),
      work(work_in),
      mu(settings_in.friction) {
  for (const Row& r : rows) speed_scale = std::max(speed_scale, r.speed);
  rescale();
  // The bodies in the problem and their start, for the energy guard.
  for (const Row& r : rows)
    for (int i : {r.a, r.b})
      if (std::find(involved.begin(), involved.end(), i) == involved.end()) involved.push_back(i);
  for (int i : involved) start.emplace_back(bodies[i].velocity, bodies[i].angular_velocity);
  kinetic_before = kinetic();
}

// One iteration of the normal stage (friction impulses held); returns the largest velocity change
// at a point (m/s).
double IslandSolver::normal_iteration() {
  double change = 0.0;
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
}

// One iteration of the friction stage (normal impulses held); returns the largest velocity change
// at a point (m/s).
double IslandSolver::friction_iteration() {
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
    const Vec2 dj = jt_new - r.jt;
    if (dj.squaredNorm() == 0.0) continue;
    apply(a, b, A, B, r, dj.x() * r.t1 + dj.y() * r.t2);
    r.jt = jt_new;
    change = std::max(change, (r.kt * dj).norm());
  }
  return change;
}

// A stage's unknowns as one vector: j_n per row, or j_t (two values) per row.
void IslandSolver::unknowns(bool friction, std::vector<double>& out) const {
  out.clear();
  for (const Row& r : rows) {
    if (!friction) out.push_back(r.jn);
    if (friction) out.insert(out.end(), {r.jt.x(), r.jt.y()});
  }
}

// How many iterations of the drift d (per iteration) the unknowns can take before one reaches its
// bound (j_n = 0, or |j_t| = mu j_n); infinity if none would.
double IslandSolver::iterations_to_bound(bool friction, const std::vector<double>& dd) const {
  double s = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < rows.size(); ++k) {
    const Row& r = rows[k];
    if (!friction) {
      if (dd[k] < 0.0) s = std::min(s, r.jn / -dd[k]);
      continue;
    }
    const Vec2 dk(dd[2 * k], dd[2 * k + 1]);
    const double d2 = dk.squaredNorm(), ad = r.jt.dot(dk), radius = mu * r.jn;
    if (d2 == 0.0) continue;
    const double disc = ad * ad - d2 * (r.jt.squaredNorm() - radius * radius);
    s = std::min(s, (-ad + std::sqrt(std::max(disc, 0.0))) / d2);
  }
  return s;
}

// Takes `count` iterations of the drift d at once: the rows' impulses and the bodies' velocities.
void IslandSolver::take_drift(bool friction, const std::vector<double>& dd, double count) {
  for (size_t k = 0; k < rows.size(); ++k) {
    Row& r = rows[k];
    Vec3 p;
    if (!friction) {
      r.jn += count * dd[k];
      p = count * dd[k] * r.n;
    } else {
      const Vec2 dk = count * Vec2(dd[2 * k], dd[2 * k + 1]);
      r.jt += dk;
      p = dk.x() * r.t1 + dk.y() * r.t2;
    }
    apply(bodies[r.a], bodies[r.b], inv[r.a], inv[r.b], r, p);
  }
}

// Converged: an iteration that changes no point's velocity by more than `convergence` of the
// problem's speeds is a fixed point to round-off (see ContactSolverSettings). The speeds are the
// bodies' at the start and the velocity change each accumulated impulse alone gives its point
// (j_n k_n): under a resting stack those are much larger than the motion and cancel, and every
// impulse applied rounds the velocities by ulps of them.
void IslandSolver::rescale() {
  double scale = speed_scale;
  for (const Row& r : rows)
    scale = std::max({scale, std::abs(r.jn) / r.normal_mass_inv, r.jt.norm() * r.kt_max});
  converged = settings.tunables.convergence * std::max(scale, 1e-300);
}

// Iterations of one stage until converged; returns how many changed something.
// Steady drift: where the targets are inconsistent with the bodies' degrees of freedom (four
// points of a face, three of them free; some get a restitution target and some rest), the
// iterations end with the same velocities every time while the impulses move along the null space
// of K by the same amount each iteration, until one reaches its bound; measured on cube tosses,
// over 10,000 iterations (the cap) with a constant violation of 4.7e-6 m/s. When two iterations in
// a row moved the impulses by the same vector (to `drift_match`), the iterations still to come
// before the first bound are taken at once, as the iteration would take them (their impulses
// applied to the bodies), and iterating goes on from there; it only ever stops at the same
// convergence test, so the answer is still the fixed point.
int IslandSolver::stage(bool friction) {
  const WorldSettings& tun = settings.tunables;
  int moving = 0;
  rescale();
  unknowns(friction, before);
  drift.clear();
  const bool budgeted = tun.iteration_budget > 0;
  for (int iteration = 0; iteration < tun.max_iterations && !(budgeted && budget_left <= 0);
       ++iteration) {
    --budget_left;
    if ((friction ? friction_iteration() : normal_iteration()) <= converged) break;
    ++moving;
    unknowns(friction, after);
    d.resize(after.size());
    double size = 0.0, off = 0.0;
    for (size_t i = 0; i < d.size(); ++i) {
      d[i] = after[i] - before[i];
      size = std::max(size, std::abs(d[i]));
      if (!drift.empty()) off = std::max(off, std::abs(d[i] - drift[i]));
    }
    if (!drift.empty() && size > 0.0 && off <= tun.drift_match * size) {
      const double count = std::floor(iterations_to_bound(friction, d)) - 1.0;
      if (count >= 1.0 && std::isfinite(count)) {
        take_drift(friction, d, count);
        ++work.drifts_taken;
        unknowns(friction, after);
        d.clear();
      }
    }
    drift.swap(d);
    before.swap(after);
  }
  work.iterations += moving;
  return moving;
}

// Staggered projections (Kaufman, Sueda, James & Pai 2008): the normal impulses with the
// friction impulses held, then the friction impulses inside the cones those normal impulses
// give, repeated until neither moves. Each stage is a convex problem that projected
// Gauss-Seidel solves to convergence; interleaving both in one iteration instead cycled at 1e-8 m/s
// on a five-cube stack (the cone radius moving under the friction rows). The active-set answer
// comes first; the projections then start from it (they find it converged) or, where it was
// refused, from zero.
void IslandSolver::solve() {
  ++work.solves;
  budget_left = settings.tunables.iteration_budget;
  if (rows.size() <= static_cast<size_t>(std::max(settings.active_set_rows, 0)))
    work.active_set += solve_active_set(bodies, inv, rows, mu, converged);
  for (int round = 0; round < settings.tunables.max_stage_rounds && !rows.empty(); ++round) {
    const int normal_moved = stage(false);
    if (!(mu > 0.0)) break;
    const int friction_moved = stage(true);
    if (round > 0 && normal_moved == 0 && friction_moved == 0) break;
    if (round == 0 && friction_moved == 0) break;
  }
}

// Kinetic energy of the bodies in the problem (J).
double IslandSolver::kinetic() const {
  double k = 0.0;
  for (int i : involved) k += bodies[i].kinetic_energy();
  return k;
}

// Solves again from the start with the restitution targets at `fraction` of Newton's.
void IslandSolver::restart(double fraction) {
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
}

// Departure from a plain Newton law: with friction, Newton's restitution on the normal
// velocity can create energy (Kane & Levinson's paradox: the friction impulse turns the body
// so the normal velocity it must reverse grows). Where the solve ended with more kinetic
// energy than it started with (beyond 1e-12 relative: round-off of an elastic frictionless
// solve), the restitution targets are scaled down, by bisection, to the largest fraction that
// adds none; at e = 0 the solve only dissipates (j_n v_n' = 0, j_t . v_t' <= 0), so a fraction
// always exists. Frictionless one-point impacts never get here (they keep the energy e^2).
void IslandSolver::guard_energy() {
  const double allowed = kinetic_before * (1.0 + 1e-12) + 1e-300;
  if (!(kinetic() > allowed && settings.restitution > 0.0)) return;
  double lo = 0.0, hi = 1.0;  // fractions: lo adds no energy, hi does
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (lo + hi);
    restart(mid);
    (kinetic() > allowed ? hi : lo) = mid;
  }
  restart(lo);
}

/// Solves one island's rows to convergence (velocities of `bodies` and the rows' accumulated
/// impulses in place): active sets first (solve_active_set, islands of up to active_set_rows
/// points), then staggered projections from their answer or from zero, and the energy guard on
/// restitution. Adds what it did to `work`.
void solve_island(std::vector<RigidBody>& bodies, const Inverses& inv, std::vector<Row>& rows,
                  const ContactSolverSettings& settings, SolverWork& work) {
  IslandSolver island(bodies, inv, rows, settings, work);
  island.solve();
  island.guard_energy();
}

// The rows of every manifold point whose pair is not both static: directions, effective
// masses, Newton's target and the convergence test's speed scale.
std::vector<Row> make_rows(const std::vector<RigidBody>& bodies, const Inverses& inv,
                           const std::vector<PairManifold>& manifolds,
                           const std::vector<std::vector<double>>& approach,
                           const ContactSolverSettings& settings) {
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
      // The scale of the convergence test is the size of the terms v_rel is summed from, not
      // |v_rel| alone: a body sliding to rest while it moves or turns carries round-off of
      // ~1e-16 of |v| + |w||r| in every v_rel, which a test relative to |v_rel| alone cannot
      // pass (measured on a cube toss at mu 0.6: one sticking point changed by 5.5e-17 m/s
      // every iteration for 10,000 iterations, against a threshold of 4.6e-17).
      const RigidBody &ba = bodies[r.a], &bb = bodies[r.b];
      const double terms = ba.velocity.norm() + ba.angular_velocity.norm() * r.ra.norm() +
                           bb.velocity.norm() + bb.angular_velocity.norm() * r.rb.norm();
      r.speed = std::max(std::abs(vn0), terms);
      rows.push_back(r);
    }
  }
  return rows;
}

// Islands: rows that share a moving body (static bodies do not join them) are one problem;
// separate islands cannot affect each other, so each is solved to its own convergence
// instead of iterating every row until the slowest island converges (many_1000: ~1,700
// iterations of every row per step for one face contact). Islands in the order of their first row.
void solve_islands(std::vector<RigidBody>& bodies, const Inverses& inv, std::vector<Row>& rows,
                   const ContactSolverSettings& settings, SolverWork& work) {
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
    solve_island(bodies, inv, island, settings, work);
    for (size_t k = 0; k < island.size(); ++k) rows[members[isl][k]] = island[k];
  }
}

}  // namespace

std::vector<SolvedPoint> solve_contact_velocities(std::vector<RigidBody>& bodies,
                                                  const std::vector<PairManifold>& manifolds,
                                                  const std::vector<std::vector<double>>& approach,
                                                  const ContactSolverSettings& settings,
                                                  SolverWork* work) {
  const Inverses inv(bodies, manifolds);
  std::vector<Row> rows = make_rows(bodies, inv, manifolds, approach, settings);
  SolverWork done;
  solve_islands(bodies, inv, rows, settings, done);
  if (work) {
    work->solves += done.solves;
    work->active_set += done.active_set;
    work->iterations += done.iterations;
    work->drifts_taken += done.drifts_taken;
  }
  // Every point's impulses, the friction impulse back in world axes.
  std::vector<SolvedPoint> out;
  out.reserve(rows.size());
  for (const Row& r : rows) {
    out.push_back({r.manifold, r.index, r.point, r.jn, r.jt.x() * r.t1 + r.jt.y() * r.t2,
                   -approach[r.manifold][r.index], r.target});
  }
  return out;
}

void project_contact_positions(std::vector<RigidBody>& bodies,
                               const std::vector<PairManifold>& manifolds,
                               const WorldSettings& tunables) {
  // Box2D's scheme; its fraction, iterations and slop are WorldSettings' (their reasons there).
  // Moving positions with the velocities held does not keep the angular momentum about the
  // origin (r x m v changes with r): measured on many_1000, the drift of 1.2e-7 (relative) is
  // this projection's (without it, 1e-15); Bullet's positional correction drifts 1.1e-6 there.
  const Inverses inv(bodies, manifolds);
  for (int it = 0; it < tunables.position_iterations; ++it)
    for (const PairManifold& pm : manifolds) {
      RigidBody &a = bodies[pm.a], &b = bodies[pm.b];
      const BodyInverse &A = inv[pm.a], &B = inv[pm.b];
      const double size_a = shape_size(*a.shape);
      const double size_b = shape_size(*b.shape);
      const double slop = tunables.position_slop * std::min(size_a, size_b);
      const Vec3& n = pm.manifold.normal;
      for (const ManifoldPoint& p : pm.manifold.points) {
        // The point's anchors on A and B moved with the bodies since detection.
        const Vec3 pa = a.pose().apply(pm.pose_a.inverse_apply(p.point));
        const Vec3 pb = b.pose().apply(pm.pose_b.inverse_apply(p.point));
        const double depth = p.depth - (pa - pb).dot(n);
        const double c = tunables.baumgarte * (depth - slop);
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
