#include "engine/dense_solve.h"

#include <Eigen/Dense>

namespace rbx {

Eigen::VectorXd least_norm_solve_refined(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(A);
  Eigen::VectorXd y = cod.solve(b);
  y += cod.solve(b - A * y);
  return y;
}

Eigen::VectorXd pivoted_qr_solve(const Eigen::MatrixXd& J, const Eigen::VectorXd& g) {
  return J.colPivHouseholderQr().solve(g);
}

}  // namespace rbx
