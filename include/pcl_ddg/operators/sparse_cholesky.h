#pragma once
/** \file
 * Sparse Cholesky factorisation of symmetric positive definite systems, for the implicit
 * smoothing steps: CHOLMOD's supernodal LLT (SuiteSparse, through Eigen's CholmodSupport) when the
 * library was built with it, Eigen's SimplicialLDLT otherwise or on request.
 *
 * The ordering and symbolic factorisation depend only on the sparsity pattern: analyzePattern()
 * once, then factorize() for every new matrix with that pattern (the values of L and M change
 * every smoothing step, the pattern does not). solve() takes several right-hand sides at once
 * (x, y, z as three columns).
 */
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>

namespace pcl_ddg {

enum class CholeskyBackend {
  Automatic,      ///< Cholmod when available, else SimplicialLDLT
  Cholmod,        ///< CHOLMOD supernodal LLT; BadArgumentException if not built in
  SimplicialLDLT  ///< Eigen's own
};

/** Whether this build of pcl_ddg has CHOLMOD. */
bool cholmodAvailable();

const char* toString(CholeskyBackend backend);

/**
 * Opt-in process-wide tuning of CHOLMOD for large systems (a million unknowns and more), which the
 * pcl_ddg tools turn on and a library user may: it changes state the host program shares, so it
 * is off by default.
 *  - CHOLMOD's allocations of 1 MiB or more are mapped with their pages populated in one call
 *    (SuiteSparse's allocator is one global, SuiteSparse_config, used by every SuiteSparse user in
 *    the process; a program that installed its own allocator keeps it): the first factorisation of
 *    a 1.15M-vertex mesh 3.4 -> 2.8 s.
 *  - During this library's CHOLMOD factorisations and solves, OpenMP regions run on the calling
 *    thread alone (omp_set_max_active_levels(0), restored after; libgomp keeps it process-wide):
 *    CHOLMOD otherwise wakes a team of four threads ~120,000 times to build relative row maps
 *    (factorisation 4.0 -> 2.8 s on two cores). The BLAS keeps its own threads.
 * Without CHOLMOD in the build it does nothing.
 */
void tuneCholmodForLargeSystems();
/** Whether tuneCholmodForLargeSystems() was called. */
bool cholmodTunedForLargeSystems();

class SparseCholesky {
 public:
  explicit SparseCholesky(CholeskyBackend backend = CholeskyBackend::Automatic);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /** The backend in use (never Automatic). */
  CholeskyBackend backend() const { return backend_; }

  /** Fill-reducing ordering and symbolic factorisation of matrix's pattern (lower triangle read).
   */
  void analyzePattern(const Eigen::SparseMatrix<double>& matrix);

  /** Numeric factorisation of a matrix with the analysed pattern; throws
   *  pcl::ComputeFailedException if it is not positive definite. */
  void factorize(const Eigen::SparseMatrix<double>& matrix);

  /** analyzePattern + factorize. */
  void compute(const Eigen::SparseMatrix<double>& matrix);

  /** Solves for every column of rhs; throws pcl::ComputeFailedException before factorize(). */
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const;
  /** The same into solution, whose storage is reused when it has the right size. */
  void solve(const Eigen::MatrixXd& rhs, Eigen::MatrixXd& solution) const;

 private:
  struct Backend;
  CholeskyBackend backend_;
  std::unique_ptr<Backend> impl_;
  bool analysed_ = false, factorised_ = false;
};

}  // namespace pcl_ddg
