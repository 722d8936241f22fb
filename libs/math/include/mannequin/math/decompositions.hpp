#pragma once
/// \file decompositions.hpp
/// \brief The Eigen decompositions mannequin uses on its dense types, compiled once.
///
/// Each decomposition below is declared `extern template` here and explicitly instantiated in
/// libs/math (src/decompositions*.cpp), so a translation unit that factors a matrix calls that one
/// compiled copy instead of instantiating the factorisation itself. Instantiating JacobiSVD<MatrixXd>
/// costs a translation unit about 18 s of g++ -O3, the complete orthogonal decomposition as much, the
/// self-adjoint eigensolver 16 s, the Cholesky factorisations 5 s each: this header is what keeps them out of every library and test that
/// uses them. Included by types.hpp; the numerics are Eigen's, unchanged. A decomposition not listed
/// here (another matrix type) is instantiated where it is used, as usual.
#include <Eigen/Dense>

namespace Eigen {
// JacobiSVD's, the QRs' and PartialPivLU's factorisations are non-template members (compute,
// computeInPlace): the class declarations cover them. LLT's, LDLT's and the eigensolver's compute()
// are member templates of the input type: declared here for the plain matrix, the input every caller
// passes (an expression as input still instantiates its own).
extern template class JacobiSVD<MatrixXd>;
extern template class JacobiSVD<Matrix3d>;
extern template class CompleteOrthogonalDecomposition<MatrixXd>;
extern template class ColPivHouseholderQR<MatrixXd>;
extern template class HouseholderQR<MatrixXd>;
extern template class PartialPivLU<MatrixXd>;
extern template class SelfAdjointEigenSolver<MatrixXd>;
extern template SelfAdjointEigenSolver<MatrixXd>& SelfAdjointEigenSolver<MatrixXd>::compute<MatrixXd>(
    const EigenBase<MatrixXd>&, int);
extern template class LLT<MatrixXd>;
extern template LLT<MatrixXd>& LLT<MatrixXd>::compute<MatrixXd>(const EigenBase<MatrixXd>&);
extern template class LDLT<MatrixXd>;
extern template LDLT<MatrixXd>& LDLT<MatrixXd>::compute<MatrixXd>(const EigenBase<MatrixXd>&);
}  // namespace Eigen
