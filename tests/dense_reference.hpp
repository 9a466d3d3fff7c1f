#pragma once
// Dense reference linear algebra for the solver tests (tests/test_solver.cpp, tests/test_multigrid.cpp):
// Eigen's decompositions and matrix products, compiled once in tests/dense_reference.cpp instead of in every
// test file that checks against them (under the sanitizers each copy took about 50 s to compile).
#include <Eigen/Dense>
#include <vector>

namespace dcm::test_dense {

// x with a x = b, a symmetric positive definite (Cholesky, LLᵀ).
Eigen::VectorXd cholesky_solve(const Eigen::MatrixXd& a, const std::vector<double>& b);

// x with a x = b, a symmetric positive or negative semi-definite (LDLᵀ with pivoting).
Eigen::VectorXd ldlt_solve(const Eigen::MatrixXd& a, const std::vector<double>& b);

// The eigenvalues of the symmetric a, ascending.
Eigen::VectorXd symmetric_eigenvalues(const Eigen::MatrixXd& a);

// pᵀ a p (the Galerkin coarse operator of a with prolongation p).
Eigen::MatrixXd galerkin_product(const Eigen::MatrixXd& p, const Eigen::MatrixXd& a);

}  // namespace dcm::test_dense
