#include "pcl_ddg/operators/sparse_cholesky.h"

#include <pcl/exceptions.h>

#include <Eigen/SparseCholesky>
#include <atomic>
#include <string>

#ifdef PCL_DDG_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>

#include "cholmod_memory.h"
#endif

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace {

std::atomic<bool> tuned_for_large_systems{false};

/// While alive, and only when tuneCholmodForLargeSystems() was called, OpenMP parallel regions
/// opened by this thread run on this thread alone. CHOLMOD 3 opens a team of a compiled-in four
/// threads for every descendant update with more than 64 rows, only to build a relative row map:
/// on a 1.15M-vertex mesh that is ~120,000 team wake-ups, which cost more than the maps. The dense
/// BLAS calls, where the flops are, keep their own threads.
class SerialOpenMpRegions {
 public:
#ifdef _OPENMP
  SerialOpenMpRegions() : active_(tuned_for_large_systems.load()) {
    if (!active_) return;
    saved_levels_ = omp_get_max_active_levels();
    omp_set_max_active_levels(0);
  }
  ~SerialOpenMpRegions() {
    if (active_) omp_set_max_active_levels(saved_levels_);
  }

 private:
  bool active_;
  int saved_levels_ = 0;
#endif
};

}  // namespace

using SparseMatrix = Eigen::SparseMatrix<double>;

struct SparseCholesky::Backend {
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> simplicial;
#ifdef PCL_DDG_HAVE_CHOLMOD
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> cholmod;
#endif
};

void tuneCholmodForLargeSystems() {
  tuned_for_large_systems = true;
#ifdef PCL_DDG_HAVE_CHOLMOD
  detail::populateCholmodAllocations();
#endif
}

bool cholmodTunedForLargeSystems() {
  return tuned_for_large_systems;
}

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
  // A matrix that is not positive definite is reported by exception, not printed by CHOLMOD.
  cholmod_common& common = impl_->cholmod.cholmod();
  common.print = 0;
  // AMD alone. CHOLMOD would follow it with METIS whenever AMD's factor looks expensive. Nested
  // dissection leaves fewer flops (4.6e10 against 7.5e10 on the 1.15M-vertex bench torus; Scotch's
  // fast strategy 5.4e10), but ordering takes 5.5 s with METIS and 1.4 s with Scotch against AMD's
  // 0.5 s, and the factorisation is no faster for it (2.4-2.6 s each, two cores).
  common.nmethods = 1;
  common.method[0].ordering = CHOLMOD_AMD;
  // Coarser supernodes than CHOLMOD's defaults ({4, 16, 48} columns), with its default share of
  // stored zeros: a mesh's elimination tree is mostly small separators, and larger dense BLAS
  // blocks pay there. More stored zeros ({0.8, 0.2, 0.1}) also made refactorisations faster, but
  // the larger factor costs more in page faults than it saves on the first one (bench_smoothing).
  common.nrelax[0] = 8;
  common.nrelax[1] = 32;
  common.nrelax[2] = 96;
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
    const SerialOpenMpRegions serial;
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
    const SerialOpenMpRegions serial;
    solution = impl_->cholmod.solve(rhs);
    return;
  }
#endif
  solution = impl_->simplicial.solve(rhs);
}

}  // namespace pcl_ddg
