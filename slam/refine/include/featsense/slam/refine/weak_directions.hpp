#pragma once
/// The directions a registration hardly constrains, from its Gauss-Newton Hessian J^T W J in
/// the tangent [rotation (rad), translation (m)]: a scene of ground and a few posts pins the
/// height, roll and pitch down a hundred times more firmly than the travel along a street, and
/// a least-squares solve slides along such a direction on whatever bias its correspondences
/// carry. Keeping the guess along the weak directions and taking the solve's correction along
/// the others is the "solution remapping" of Zhang, Kaess and Singh (ICRA 2016, "On
/// degeneracy of optimization-based state estimation problems").

#include <Eigen/Core>

namespace featsense::slam::refine {

struct WeakDirections {
  /// Projects a tangent step onto the directions constrained well enough (identity when all
  /// are); apply it to a correction to keep the guess along the weak ones.
  Eigen::Matrix<double, 6, 6> keep_strong = Eigen::Matrix<double, 6, 6>::Identity();
  int count = 0;  ///< directions held
  /// The weakest eigenvalue over the strongest, rotations weighed at the lever arm.
  double weakest_ratio = 1.0;
};

/// A direction whose eigenvalue is below `min_ratio` times the largest one is weak, a turn
/// weighed as the motion it gives a point `lever_arm_m` from the centre of rotation (the
/// registered points' RMS distance from it, so that a turn in a small room counts as much as
/// one in a street). A non-finite or zero Hessian makes every direction weak; `min_ratio` <= 0
/// none.
WeakDirections weak_directions(const Eigen::Matrix<double, 6, 6>& hessian, double lever_arm_m,
                               double min_ratio);

}  // namespace featsense::slam::refine
