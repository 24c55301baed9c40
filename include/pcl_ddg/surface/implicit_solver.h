#pragma once
// How an implicit (backward Euler) step solves (M - tau L) X' = M X.
//
// Cholesky factorises the system (sparse_cholesky.h): exact to rounding for any tau, and one
// factor serves every later step with the same operator, but a first factorisation costs as much
// as about 300 conjugate-gradient iterations on a mesh of any size (1.15M vertices: 3 s).
//
// ConjugateGradient solves for the displacement D = X' - X instead,
//   (M - tau L) D = tau L X        (L X summed as differences, so scans far from the origin keep
//                                   the displacement's digits),
// with Eigen's Jacobi-preconditioned ConjugateGradient to a residual of 1e-12 of tau L X. On the
// free vertices M - tau L >= M, so the Jacobi-scaled system's condition number is at most
//   kappa = max_i (sum_j |A_ij| / A_ii) / min_i (m_i / A_ii)       (A = M - tau L),
// independent of the mesh size for steps of a fixed number of h^2: a step of 1 h^2 takes some 30
// iterations per column. A run that does not converge within twice its iteration bound is an
// error (forced) or finishes with Cholesky (Automatic).
//
// Automatic compares the two for the whole run before its first step: conjugate gradients cost
// the bound's iterations for every step and column, Cholesky a factorisation per new operator
// (once for a frozen operator, every step when the mass follows the surface) plus its solves.
namespace pcl_ddg {

enum class ImplicitSolver { Automatic, Cholesky, ConjugateGradient };

const char* toString(ImplicitSolver solver);

}  // namespace pcl_ddg
