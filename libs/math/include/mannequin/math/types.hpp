#pragma once
/// \file types.hpp
/// \brief Eigen aliases shared by every mannequin library (scalar: double).
#include <Eigen/Dense>

#include "mannequin/math/decompositions.hpp"

namespace mannequin::math {

using Vector3 = Eigen::Vector3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix3 = Eigen::Matrix3d;
using Matrix4 = Eigen::Matrix4d;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using MatrixX = Eigen::MatrixXd;
using VectorX = Eigen::VectorXd;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;
using Matrix3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;

}  // namespace mannequin::math
