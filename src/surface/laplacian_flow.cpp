#include "laplacian_flow.h"

#include <pcl/exceptions.h>

#include <algorithm>
#include <string>
#include <utility>

namespace pcl_ddg {
namespace detail {

LaplacianFlow::LaplacianFlow(int num_vertices, std::vector<char> fixed, CholeskyBackend backend)
    : num_vertices_(num_vertices), fixed_(std::move(fixed)), solver_(backend) {
  if (fixed_.empty()) fixed_.assign(num_vertices_, 0);
  if (static_cast<int>(fixed_.size()) != num_vertices_) {
    throw pcl::BadArgumentException("fixed-vertex mask of the wrong size");
  }
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
  factor_current_ = false;
}

void LaplacianFlow::setMass(Eigen::VectorXd mass) {
  if (mass.size() != num_vertices_) throw pcl::BadArgumentException("mass of the wrong size");
  mass_ = std::move(mass);
  factor_current_ = false;
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
  if (!factor_current_ || tau != factor_tau_) {
    fillSystem(tau);
    if (!pattern_analysed_) {
      solver_.analyzePattern(system_);
      pattern_analysed_ = true;
    }
    solver_.factorize(system_);
    factor_current_ = true;
    factor_tau_ = tau;
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
