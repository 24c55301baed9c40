#pragma once
/** \file
 * How an implicit (backward Euler) step solves (M - tau L) X' = M X.
 *
 * Cholesky factorises the system (sparse_cholesky.h): exact to rounding for any tau, and one
 * factor serves every later step with the same operator, but a first factorisation costs as much
 * as about 300 conjugate-gradient iterations on a mesh of any size (1.15M vertices: 3 s).
 *
 * ConjugateGradient solves for the displacement D = X' - X instead,
 *   (M - tau L) D = tau L X        (L X summed as differences, so scans far from the origin keep
 *                                   the displacement's digits),
 * with Eigen's Jacobi-preconditioned ConjugateGradient to a residual of 1e-12 of tau L X. On the
 * free vertices M - tau L >= M, so the Jacobi-scaled system's condition number is at most
 *   kappa = max_i (sum_j |A_ij| / A_ii) / min_i (m_i / A_ii)       (A = M - tau L),
 * independent of the mesh size for steps of a fixed number of h^2. Steps of 1 h^2 take 35-100
 * iterations per column on the shared scans and the bench torus, steps of 10 h^2 120-240. Forced
 * conjugate gradients that do not converge within twice the worst-case iterations for kappa are
 * an error.
 *
 * Automatic tries conjugate gradients on the first step's first column, stopped at the
 * iterations where the run's Cholesky (a factorisation per new operator, plus its solves) would
 * cost as much per column. If they converge the run iterates; otherwise it factorises, having
 * spent at most that share of a Cholesky step. So one step of 1 h^2 iterates, a frozen operator
 * over many steps or steps of 10 h^2 and more factorise.
 */
#include <string>

#include "pcl_ddg/operators/sparse_cholesky.h"
#include "pcl_ddg/option_style.h"

namespace pcl_ddg {

enum class ImplicitSolver { Automatic, Cholesky, ConjugateGradient };

const char* toString(ImplicitSolver solver);

struct SolverChoice {
  ImplicitSolver method;
  CholeskyBackend backend;
};

/** solver auto | cholmod | ldlt | cg: auto picks the cheaper of Cholesky and conjugate gradients
 *  for the run; cholmod and ldlt factorise with that backend; cg always iterates. */
inline SolverChoice chooseSolver(const std::string& name, const OptionStyle& style) {
  return chooseNamed<SolverChoice>(
      "solver", name,
      {{"auto", {ImplicitSolver::Automatic, CholeskyBackend::Automatic}},
       {"cholmod", {ImplicitSolver::Cholesky, CholeskyBackend::Cholmod}},
       {"ldlt", {ImplicitSolver::Cholesky, CholeskyBackend::SimplicialLDLT}},
       {"cg", {ImplicitSolver::ConjugateGradient, CholeskyBackend::Automatic}}},
      style);
}

}  // namespace pcl_ddg
