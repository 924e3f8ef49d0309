#pragma once
/// Huber's loss folded into a residual, so that many residuals can share one Ceres cost
/// function (and its per-block overhead) while each keeps its own robust loss.
///
/// With s = |r|^2 and Huber's rho (Ceres' HuberLoss: rho(s) = s up to delta^2, then
/// 2 delta sqrt(s) - delta^2), the folded residual r' = f r with f = sqrt(rho(s) / s) has
/// 1/2 |r'|^2 = 1/2 rho(s): the same cost. Its exact Jacobian is
///   J' = f J + (rho'(s) s - rho(s)) / (s^2 f) r (r^T J),
/// so the gradient J'^T r' = rho'(s) J^T r is the robust cost's as well: the solver's steps
/// and its minimum are those of the loss applied by Ceres.

namespace featsense::slam::odometry {

/// Folds the loss into `residual` (`rows` values) and its Jacobians, row-major: `jacobian_q`
/// rows x 4 and `jacobian_t` rows x 3 (either may be null). Returns rho(s).
double fold_huber(double delta, int rows, double* residual, double* jacobian_q, double* jacobian_t);

}  // namespace featsense::slam::odometry
