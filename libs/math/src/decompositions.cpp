// The eigensolver, QR, LU and Cholesky decompositions declared in decompositions.hpp.
#include "mannequin/math/decompositions.hpp"

namespace Eigen {
template class ColPivHouseholderQR<MatrixXd>;
template class HouseholderQR<MatrixXd>;
template class PartialPivLU<MatrixXd>;
template class SelfAdjointEigenSolver<MatrixXd>;
template SelfAdjointEigenSolver<MatrixXd>& SelfAdjointEigenSolver<MatrixXd>::compute<MatrixXd>(
    const EigenBase<MatrixXd>&, int);
template class LLT<MatrixXd>;
template LLT<MatrixXd>& LLT<MatrixXd>::compute<MatrixXd>(const EigenBase<MatrixXd>&);
template class LDLT<MatrixXd>;
template LDLT<MatrixXd>& LDLT<MatrixXd>::compute<MatrixXd>(const EigenBase<MatrixXd>&);
}  // namespace Eigen
