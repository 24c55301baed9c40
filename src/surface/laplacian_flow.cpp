#include "laplacian_flow.h"

#include <pcl/exceptions.h>

#include <Eigen/IterativeLinearSolvers>
#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace pcl_ddg {

const char* toString(ImplicitSolver solver) {
  switch (solver) {
    case ImplicitSolver::Automatic:
      return "automatic";
    case ImplicitSolver::Cholesky:
      return "Cholesky";
    case ImplicitSolver::ConjugateGradient:
      return "conjugate gradients";
  }
  return "?";
}

namespace detail {
namespace {

// Residual of the displacement's system relative to its right-hand side tau L X: the solution then
// agrees with a Cholesky solve of the positions to rounding (test_implicit_solver).
constexpr double kConjugateGradientTolerance = 1e-12;

// Costs in conjugate-gradient iterations (one sparse matrix-vector product and a few vector
// operations), measured with bench_smoothing's tori from 18k to 1.15M vertices, two threads: a
// CHOLMOD factorisation with its analysis 240-390 iterations at every size, a solve 10-17 per
// column; Eigen's SimplicialLDLT factorises in about 4 sqrt(n).
constexpr double kCholmodFactorisationCost = 300.0;
constexpr double kSimplicialFactorisationCostPerRootVertex = 4.0;
constexpr double kCholeskySolveCostPerColumn = 15.0;

}  // namespace

LaplacianFlow::LaplacianFlow(int num_vertices, std::vector<char> fixed, CholeskyBackend backend,
                             ImplicitSolver solver)
    : num_vertices_(num_vertices),
      fixed_(std::move(fixed)),
      solver_(backend),
      method_(solver),
      automatic_(solver == ImplicitSolver::Automatic) {
  if (fixed_.empty()) fixed_.assign(num_vertices_, 0);
  if (static_cast<int>(fixed_.size()) != num_vertices_) {
    throw pcl::BadArgumentException("fixed-vertex mask of the wrong size");
  }
}

void LaplacianFlow::planSteps(int steps, int new_operators) {
  planned_steps_ = std::max(steps, 1);
  planned_new_operators_ = std::clamp(new_operators, 1, planned_steps_);
}

void LaplacianFlow::setOperator(Eigen::SparseMatrix<double> laplacian, Eigen::VectorXd mass) {
  if (laplacian.rows() != num_vertices_ || laplacian.cols() != num_vertices_ ||
      mass.size() != num_vertices_) {
    throw pcl::BadArgumentException("Laplacian or mass of the wrong size");
  }
  laplacian.makeCompressed();
  const bool same_pattern =
      laplacian_.nonZeros() == laplacian.nonZeros() && laplacian_.rows() == laplacian.rows() &&
      std::equal(laplacian.outerIndexPtr(), laplacian.outerIndexPtr() + num_vertices_ + 1,
                 laplacian_.outerIndexPtr()) &&
      std::equal(laplacian.innerIndexPtr(), laplacian.innerIndexPtr() + laplacian.nonZeros(),
                 laplacian_.innerIndexPtr());
  laplacian_.swap(laplacian);  // Eigen 3.4's SparseMatrix has no move assignment
  mass_ = std::move(mass);
  if (!have_free_set_) chooseFreeVertices();
  if (!same_pattern) {
    buildSystemPattern();
    pattern_analysed_ = false;
  }
  system_current_ = factor_current_ = false;
}

void LaplacianFlow::setMass(Eigen::VectorXd mass) {
  if (mass.size() != num_vertices_) throw pcl::BadArgumentException("mass of the wrong size");
  mass_ = std::move(mass);
  system_current_ = factor_current_ = false;
}

void LaplacianFlow::chooseFreeVertices() {
  compact_.assign(num_vertices_, -1);
  free_vertices_.clear();
  for (int v = 0; v < num_vertices_; ++v) {
    if (fixed_[v] || !(mass_[v] > 0.0)) continue;
    compact_[v] = static_cast<int>(free_vertices_.size());
    free_vertices_.push_back(v);
  }
  have_free_set_ = true;
}

void LaplacianFlow::buildSystemPattern() {
  // Columns of L in vertex order restricted to free rows: the compact numbering is increasing in
  // the vertex numbering, so every column stays sorted and the CSC arrays are written directly.
  const int n = numFree();
  std::vector<int> outer(n + 1, 0), inner;
  source_entry_.clear();
  diagonal_entry_.assign(n, -1);
  inner.reserve(laplacian_.nonZeros());
  source_entry_.reserve(laplacian_.nonZeros());
  for (int c = 0; c < n; ++c) {
    const int column = free_vertices_[c];
    for (int k = laplacian_.outerIndexPtr()[column]; k < laplacian_.outerIndexPtr()[column + 1];
         ++k) {
      const int row = compact_[laplacian_.innerIndexPtr()[k]];
      if (row < 0) continue;
      if (row == c) diagonal_entry_[c] = static_cast<int>(inner.size());
      inner.push_back(row);
      source_entry_.push_back(k);
    }
    outer[c + 1] = static_cast<int>(inner.size());
  }
  system_ = Eigen::SparseMatrix<double>(n, n);
  system_.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), system_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), system_.innerIndexPtr());
  for (int c = 0; c < n; ++c) {
    if (diagonal_entry_[c] < 0) {
      throw pcl::ComputeFailedException("vertex " + std::to_string(free_vertices_[c]) +
                                        " has mass but no Laplacian row");
    }
  }
}

void LaplacianFlow::fillSystem(double tau) {
  double* values = system_.valuePtr();
  const double* weights = laplacian_.valuePtr();
  for (std::size_t k = 0; k < source_entry_.size(); ++k)
    values[k] = -tau * weights[source_entry_[k]];
  for (int c = 0; c < numFree(); ++c) values[diagonal_entry_[c]] += mass_[free_vertices_[c]];
}

void LaplacianFlow::explicitStep(Eigen::MatrixXd& values, double tau) const {
  const Eigen::MatrixXd change = laplacian_ * values;
  for (const int v : free_vertices_) {
    if (mass_[v] > 0.0) values.row(v) += (tau / mass_[v]) * change.row(v);
  }
}

void LaplacianFlow::implicitStep(Eigen::MatrixXd& values, double tau) {
  if (numFree() == 0) return;  // every value constrained: nothing to solve for
  if (!system_current_ || tau != system_tau_) {
    fillSystem(tau);
    system_current_ = true;
    system_tau_ = tau;
    factor_current_ = false;
  }
  if (method_ != ImplicitSolver::Cholesky) {
    if (conjugateGradientStep(values, tau)) {
      method_ = ImplicitSolver::ConjugateGradient;
      return;
    }
    if (!automatic_) {
      throw pcl::ComputeFailedException(
          "conjugate gradients did not converge within twice their iteration bound (" +
          std::to_string(conjugateGradientIterationBound()) + "): use the Cholesky solver");
    }
    method_ = ImplicitSolver::Cholesky;
  }
  choleskyStep(values, tau);
}

int LaplacianFlow::trialIterations(int columns) const {
  const double factorisation =
      backend() == CholeskyBackend::Cholmod
          ? kCholmodFactorisationCost
          : kSimplicialFactorisationCostPerRootVertex * std::sqrt(static_cast<double>(numFree()));
  return static_cast<int>(std::ceil(planned_new_operators_ * factorisation /
                                        (static_cast<double>(planned_steps_) * columns) +
                                    kCholeskySolveCostPerColumn));
}

int LaplacianFlow::conjugateGradientIterationBound() const {
  // The Jacobi-scaled system D^-1 A (A = M - tau L on the free vertices, D its diagonal): A >= M
  // bounds its smallest eigenvalue below by min m_i / A_ii, Gershgorin its largest above by
  // max sum_j |A_ij| / A_ii (columns are rows: A is symmetric).
  double smallest = std::numeric_limits<double>::infinity(), largest = 0.0;
  const double* a = system_.valuePtr();
  const int* outer = system_.outerIndexPtr();
#pragma omp parallel for reduction(min : smallest) reduction(max : largest)
  for (int c = 0; c < numFree(); ++c) {
    double row = 0.0;
    for (int k = outer[c]; k < outer[c + 1]; ++k) row += std::abs(a[k]);
    const double diagonal = a[diagonal_entry_[c]];
    smallest = std::min(smallest, mass_[free_vertices_[c]] / diagonal);
    largest = std::max(largest, row / diagonal);
  }
  // In the worst case the error's A-norm shrinks by (sqrt(kappa) - 1) / (sqrt(kappa) + 1) an
  // iteration, from at most 2 sqrt(kappa) times the tolerated residual.
  const double root_kappa = std::sqrt(std::max(largest / smallest, 1.0));
  const double rate = (root_kappa - 1.0) / (root_kappa + 1.0);
  if (!(rate > 0.0)) return 1;
  const double bound =
      std::ceil(std::log(kConjugateGradientTolerance / (2.0 * root_kappa)) / std::log(rate));
  return bound < INT_MAX / 4 ? std::max(static_cast<int>(bound), 1) : INT_MAX / 4;
}

bool LaplacianFlow::conjugateGradientStep(Eigen::MatrixXd& values, double tau) {
  const int n = numFree();
  const Eigen::Index columns = values.cols();
  // The right-hand side tau L X on the free rows, summed as differences x_u - x_v: L's rows sum
  // to zero, and far from the origin the sum of w x_u would cancel the displacement's digits.
  rhs_.resize(n, columns);
  const int* outer = laplacian_.outerIndexPtr();
  const int* inner = laplacian_.innerIndexPtr();
  const double* weight = laplacian_.valuePtr();
#pragma omp parallel for schedule(static)
  for (int c = 0; c < n; ++c) {
    const int v = free_vertices_[c];
    for (Eigen::Index column = 0; column < columns; ++column) {
      double sum = 0.0;
      for (int k = outer[v]; k < outer[v + 1]; ++k) {
        if (inner[k] != v) sum += weight[k] * (values(inner[k], column) - values(v, column));
      }
      rhs_(c, column) = tau * sum;
    }
  }
  // The system is symmetric, so its column-major arrays read as row-major: the form whose
  // products Eigen runs on several threads.
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>> system(
      n, n, system_.nonZeros(), system_.outerIndexPtr(), system_.innerIndexPtr(),
      system_.valuePtr());
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double, Eigen::RowMajor>,
                           Eigen::Lower | Eigen::Upper>
      cg;
  cg.setTolerance(kConjugateGradientTolerance);
  const int safe_iterations = 2 * conjugateGradientIterationBound();
  // Automatic's first column is a trial: stopped where the run's Cholesky would cost less.
  cg.setMaxIterations(method_ == ImplicitSolver::Automatic
                          ? std::min(trialIterations(static_cast<int>(columns)), safe_iterations)
                          : safe_iterations);
  cg.compute(system);
  solution_.resize(n, columns);
  for (Eigen::Index column = 0; column < columns; ++column) {
    solution_.col(column) = cg.solve(rhs_.col(column));
    cg_iterations_ += cg.iterations();
    if (cg.info() != Eigen::Success) return false;
    cg.setMaxIterations(safe_iterations);
  }
  for (int c = 0; c < n; ++c) values.row(free_vertices_[c]) += solution_.row(c);
  return true;
}

void LaplacianFlow::choleskyStep(Eigen::MatrixXd& values, double tau) {
  if (!factor_current_) {
    if (!pattern_analysed_) {
      solver_.analyzePattern(system_);
      pattern_analysed_ = true;
    }
    solver_.factorize(system_);
    factor_current_ = true;
  }
  // rhs_ and solution_ keep their storage from step to step: at a million vertices each is 27 MB
  // that would otherwise be page-faulted in again.
  rhs_.resize(numFree(), values.cols());
  for (int c = 0; c < numFree(); ++c) {
    rhs_.row(c) = mass_[free_vertices_[c]] * values.row(free_vertices_[c]);
  }
  if (numFree() < num_vertices_) {
    // The constrained values' pull on their free neighbours: tau * L_fc * X_c.
    Eigen::MatrixXd constrained = values;
    for (const int v : free_vertices_) constrained.row(v).setZero();
    const Eigen::MatrixXd pull = laplacian_ * constrained;
    for (int c = 0; c < numFree(); ++c) rhs_.row(c) += tau * pull.row(free_vertices_[c]);
  }
  solver_.solve(rhs_, solution_);
  for (int c = 0; c < numFree(); ++c) values.row(free_vertices_[c]) = solution_.row(c);
}

}  // namespace detail
}  // namespace pcl_ddg
