#pragma once
// Time steps of the Laplacian flow dX/dt = M^-1 L X of per-vertex values (n x c: positions as three
// columns, or scalar fields), the engine under mesh and scalar-field smoothing.
//
//   explicit (forward Euler)   X <- X + tau M^-1 L X
//   implicit (backward Euler)  (M - tau L) X' = M X       (symmetric positive definite)
//
// Constrained vertices (fixed boundary, and vertices of zero mass: isolated, or only on degenerate
// triangles) keep their values; the implicit system is solved for the free vertices only, with
// the constrained values moved to the right-hand side (with nothing free, a step changes nothing).
// The system is solved by sparse Cholesky or conjugate gradients (implicit_solver.h); with
// Cholesky the pattern is analysed once, and a new operator (same mesh, new values) or a new tau
// only refactorises.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "pcl_ddg/operators/sparse_cholesky.h"
#include "pcl_ddg/surface/implicit_solver.h"

namespace pcl_ddg {
namespace detail {

class LaplacianFlow {
 public:
  /** fixed[v] != 0 keeps vertex v's values (empty: none fixed by the caller). */
  LaplacianFlow(int num_vertices, std::vector<char> fixed, CholeskyBackend backend,
                ImplicitSolver solver = ImplicitSolver::Automatic);

  /** What ImplicitSolver::Automatic weighs: the implicit steps of the run, and how many of them
   *  start with a new operator (setOperator or setMass since the last). Default: one and one. */
  void planSteps(int steps, int new_operators);

  /** The summed (symmetric, negative semi-definite) Laplacian and the lumped masses. */
  void setOperator(Eigen::SparseMatrix<double> laplacian, Eigen::VectorXd mass);

  /** New masses with the Laplacian kept (frozen stiffness); the free set stays as first chosen. */
  void setMass(Eigen::VectorXd mass);

  void explicitStep(Eigen::MatrixXd& values, double tau) const;

  /** Throws pcl::ComputeFailedException when (M - tau L) on the free vertices is not positive
   *  definite (a free vertex without mass and without edges), or when forced conjugate gradients
   *  do not converge. */
  void implicitStep(Eigen::MatrixXd& values, double tau);

  CholeskyBackend backend() const { return solver_.backend(); }
  /** Cholesky or ConjugateGradient once an implicit step has chosen (Automatic before). */
  ImplicitSolver implicitSolver() const { return method_; }
  /** Conjugate gradients' worst-case iterations per column for the system of the last implicit
   *  step (implicit_solver.h). */
  int conjugateGradientIterationBound() const;
  /** Conjugate-gradient iterations so far, summed over steps and columns (an abandoned trial
   *  included). */
  long conjugateGradientIterations() const { return cg_iterations_; }
  int numFree() const { return static_cast<int>(free_vertices_.size()); }

 private:
  void chooseFreeVertices();
  void buildSystemPattern();
  void fillSystem(double tau);
  /** Automatic's trial: the iterations per column at which the run's Cholesky costs as much. */
  int trialIterations(int columns) const;
  /** false if it did not converge (values untouched). */
  bool conjugateGradientStep(Eigen::MatrixXd& values, double tau);
  void choleskyStep(Eigen::MatrixXd& values, double tau);

  int num_vertices_;
  std::vector<char> fixed_;
  Eigen::SparseMatrix<double> laplacian_;
  Eigen::VectorXd mass_;
  bool have_free_set_ = false;
  std::vector<int> free_vertices_;  ///< compact index -> vertex
  std::vector<int> compact_;        ///< vertex -> compact index, or -1 if constrained

  // (M - tau L) restricted to the free vertices, and for each of its entries the entry of L it
  // comes from (the pattern is fixed, so refilling is a gather).
  Eigen::SparseMatrix<double> system_;
  std::vector<int> source_entry_;
  std::vector<int> diagonal_entry_;  ///< per free vertex: its diagonal entry in system_
  SparseCholesky solver_;
  ImplicitSolver method_;
  bool automatic_;  ///< method_ chosen by a trial, falling back to Cholesky
  int planned_steps_ = 1, planned_new_operators_ = 1;
  long cg_iterations_ = 0;
  Eigen::MatrixXd rhs_, solution_;  ///< implicit step buffers, free vertices x value columns
  bool pattern_analysed_ = false, system_current_ = false, factor_current_ = false;
  double system_tau_ = 0.0;
};

}  // namespace detail
}  // namespace pcl_ddg
