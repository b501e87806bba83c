// The contact solver's dense solves (its active sets, engine/contact_solver.cpp), compiled in a
// file of their own: Eigen's decompositions are most of that file's compile time, so an edit to
// the solver's logic rebuilds without them (docs/testing.md).
#pragma once

#include <Eigen/Core>

namespace rbx {

/// The least-norm least-squares answer y of A y = b (a complete orthogonal decomposition), with
/// one step of iterative refinement: the residual of the first solve solved again and added,
/// which takes the answer's round-off from cond(A) ulps down to a few.
Eigen::VectorXd least_norm_solve_refined(const Eigen::MatrixXd& A, const Eigen::VectorXd& b);

/// The least-squares answer s of J s = g (Householder QR with column pivoting).
Eigen::VectorXd pivoted_qr_solve(const Eigen::MatrixXd& J, const Eigen::VectorXd& g);

}  // namespace rbx
