#include "featsense/slam/odometry/huber_folding.hpp"

#include <cmath>

namespace featsense::slam::odometry {
namespace {

/// J <- f J + c r (r^T J) for a row-major rows x cols Jacobian.
void fold_jacobian(int rows, int cols, const double* r, double f, double c, double* jacobian) {
  if (jacobian == nullptr) return;
  double rtj[4] = {0.0, 0.0, 0.0, 0.0};  // r^T J, cols <= 4
  for (int col = 0; col < cols; ++col) {
    for (int row = 0; row < rows; ++row) rtj[col] += r[row] * jacobian[row * cols + col];
  }
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      jacobian[row * cols + col] = f * jacobian[row * cols + col] + c * r[row] * rtj[col];
    }
  }
}

}  // namespace

double fold_huber(double delta, int rows, double* residual, double* jacobian_q,
                  double* jacobian_t) {
  double s = 0.0;
  for (int row = 0; row < rows; ++row) s += residual[row] * residual[row];
  const double delta2 = delta * delta;
  if (s <= delta2) return s;  // the quadratic part: nothing changes
  const double root = std::sqrt(s);
  const double rho = 2.0 * delta * root - delta2;
  const double rho1 = delta / root;
  const double f = std::sqrt(rho / s);
  const double c = (rho1 * s - rho) / (s * s * f);
  // The Jacobians first: they need the residual before it is scaled.
  fold_jacobian(rows, 4, residual, f, c, jacobian_q);
  fold_jacobian(rows, 3, residual, f, c, jacobian_t);
  for (int row = 0; row < rows; ++row) residual[row] *= f;
  return rho;
}

}  // namespace featsense::slam::odometry
