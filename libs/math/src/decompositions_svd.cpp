// The singular-value and complete orthogonal decompositions declared in decompositions.hpp.
#include "mannequin/math/decompositions.hpp"

namespace Eigen {
template class JacobiSVD<MatrixXd>;
template class JacobiSVD<Matrix3d>;
template class CompleteOrthogonalDecomposition<MatrixXd>;
}  // namespace Eigen
