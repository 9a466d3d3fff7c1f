#include "tests/dense_reference.hpp"

namespace dcm::test_dense {

namespace {
Eigen::Map<const Eigen::VectorXd> as_eigen(const std::vector<double>& b) {
  return {b.data(), static_cast<Eigen::Index>(b.size())};
}
}  // namespace

Eigen::VectorXd cholesky_solve(const Eigen::MatrixXd& a, const std::vector<double>& b) {
  return a.llt().solve(as_eigen(b));
}

Eigen::VectorXd ldlt_solve(const Eigen::MatrixXd& a, const std::vector<double>& b) {
  return a.ldlt().solve(as_eigen(b));
}

Eigen::VectorXd symmetric_eigenvalues(const Eigen::MatrixXd& a) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a, Eigen::EigenvaluesOnly);
  return eig.eigenvalues();
}

Eigen::MatrixXd galerkin_product(const Eigen::MatrixXd& p, const Eigen::MatrixXd& a) {
  return p.transpose() * a * p;
}

}  // namespace dcm::test_dense
