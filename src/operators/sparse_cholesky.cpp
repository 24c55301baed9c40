#include "pcl_ddg/operators/sparse_cholesky.h"

#include <pcl/exceptions.h>

#include <Eigen/SparseCholesky>
#include <string>

#ifdef PCL_DDG_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>

#include "cholmod_huge_pages.h"
#endif

namespace pcl_ddg {

using SparseMatrix = Eigen::SparseMatrix<double>;

struct SparseCholesky::Backend {
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> simplicial;
#ifdef PCL_DDG_HAVE_CHOLMOD
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> cholmod;
#endif
};

bool cholmodAvailable() {
#ifdef PCL_DDG_HAVE_CHOLMOD
  return true;
#else
  return false;
#endif
}

const char* toString(CholeskyBackend backend) {
  switch (backend) {
    case CholeskyBackend::Automatic:
      return "automatic";
    case CholeskyBackend::Cholmod:
      return "CHOLMOD";
    case CholeskyBackend::SimplicialLDLT:
      return "SimplicialLDLT";
  }
  return "?";
}

SparseCholesky::SparseCholesky(CholeskyBackend backend)
    : backend_(backend), impl_(std::make_unique<Backend>()) {
  if (backend_ == CholeskyBackend::Automatic) {
    backend_ = cholmodAvailable() ? CholeskyBackend::Cholmod : CholeskyBackend::SimplicialLDLT;
  }
  if (backend_ == CholeskyBackend::Cholmod && !cholmodAvailable()) {
    throw pcl::BadArgumentException(
        "pcl_ddg was built without CHOLMOD (install libsuitesparse-dev)");
  }
#ifdef PCL_DDG_HAVE_CHOLMOD
  detail::adviseHugePagesForCholmod();
  // A matrix that is not positive definite is reported by exception, not printed by CHOLMOD.
  cholmod_common& common = impl_->cholmod.cholmod();
  common.print = 0;
  // AMD alone. CHOLMOD would follow it with METIS whenever AMD's factor looks expensive: nested
  // dissection leaves less fill (2.3x fewer flops on a scanned head), but ordering 1.15M vertices
  // takes 6 s against AMD's 0.4 s, and with the supernodes below a smoothing step is no faster
  // for it (4.6 s either way, bench_smoothing on two cores).
  common.nmethods = 1;
  common.method[0].ordering = CHOLMOD_AMD;
  // Coarser supernodes than CHOLMOD's defaults ({4, 16, 48} columns, {0.8, 0.1, 0.05} explicit
  // zeros): a mesh's elimination tree is mostly small separators, where a few stored zeros buy
  // larger dense BLAS blocks. Refactorising the 1.15M-vertex system takes 3.4 s instead of 6.6 s;
  // a 100k-vertex one 0.21 s instead of 0.41 s.
  common.nrelax[0] = 16;
  common.nrelax[1] = 64;
  common.nrelax[2] = 128;
  common.zrelax[0] = 0.8;
  common.zrelax[1] = 0.2;
  common.zrelax[2] = 0.1;
#endif
}

SparseCholesky::~SparseCholesky() = default;

void SparseCholesky::analyzePattern(const SparseMatrix& matrix) {
#ifdef PCL_DDG_HAVE_CHOLMOD
  if (backend_ == CholeskyBackend::Cholmod) {
    impl_->cholmod.analyzePattern(matrix);
  } else
#endif
  {
    impl_->simplicial.analyzePattern(matrix);
  }
  analysed_ = true;
  factorised_ = false;
}

void SparseCholesky::factorize(const SparseMatrix& matrix) {
  if (!analysed_) analyzePattern(matrix);
  Eigen::ComputationInfo info;
#ifdef PCL_DDG_HAVE_CHOLMOD
  if (backend_ == CholeskyBackend::Cholmod) {
    impl_->cholmod.factorize(matrix);
    info = impl_->cholmod.info();
  } else
#endif
  {
    impl_->simplicial.factorize(matrix);
    info = impl_->simplicial.info();
    // LDLT also factorises indefinite matrices: positive definite means a positive diagonal D.
    if (info == Eigen::Success && !(impl_->simplicial.vectorD().minCoeff() > 0.0)) {
      info = Eigen::NumericalIssue;
    }
  }
  factorised_ = info == Eigen::Success;
  if (!factorised_) {
    throw pcl::ComputeFailedException(std::string(toString(backend_)) +
                                      ": the matrix is not positive definite");
  }
}

void SparseCholesky::compute(const SparseMatrix& matrix) {
  analyzePattern(matrix);
  factorize(matrix);
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& rhs) const {
  Eigen::MatrixXd solution;
  solve(rhs, solution);
  return solution;
}

void SparseCholesky::solve(const Eigen::MatrixXd& rhs, Eigen::MatrixXd& solution) const {
  if (!factorised_) {
    throw pcl::ComputeFailedException("solve() before a successful factorize()");
  }
#ifdef PCL_DDG_HAVE_CHOLMOD
  if (backend_ == CholeskyBackend::Cholmod) {
    solution = impl_->cholmod.solve(rhs);
    return;
  }
#endif
  solution = impl_->simplicial.solve(rhs);
}

}  // namespace pcl_ddg
