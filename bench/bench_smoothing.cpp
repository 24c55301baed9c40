// One implicit cotangent smoothing step on a 1.15M-vertex torus, everything included (rebuilding
// L and M from the positions, assembling M - tau L, solving for x, y, z): the first step by the
// default solver, by CHOLMOD's supernodal LLT and by Eigen's SimplicialLDLT, then a later step
// (pattern analysed already). Then the factorisation alone: the first one (ordering and analysis
// included), and a later one with the symbolic analysis reused and redone.
#include <benchmark/benchmark.h>

#include <chrono>
#include <vector>

#include "bench_support.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/operators/sparse_cholesky.h"
#include "pcl_ddg/surface/implicit_solver.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace pcl_ddg {
namespace bench {
namespace {

constexpr int kAround = 1536, kTube = 750;  // 1,152,000 vertices

struct Fixture {
  const BenchMesh& mesh = torusMesh(kAround, kTube);
  MeshTopology topology{static_cast<int>(mesh.points.cols()), mesh.triangles};
  double tau = 0.0;
  Eigen::SparseMatrix<double> system;  ///< M - tau L of the input

  Fixture() {
    const double h = meanEdgeLength(topology, mesh.points);
    tau = 1.0 * h * h;
    system = -tau * laplacian(topology, mesh.points);
    system.diagonal() += lumpedMass(topology, mesh.points);
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

void implicitStep(benchmark::State& state, ImplicitSolver method, CholeskyBackend backend) {
  const Fixture& f = fixture();
  MeshSmoothingParameters p;
  p.time_step = f.tau;
  p.implicit_solver = method;
  p.solver = backend;
  for (auto _ : state) {
    const Eigen::Matrix3Xd x = smoothMeshPositions(f.topology, f.mesh.points, p);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["vertices"] = static_cast<double>(f.mesh.points.cols());
}
// The default (one small step: conjugate gradients), CHOLMOD forced, and Eigen's SimplicialLDLT
// forced (the solver of libigl's smoothing tutorial).
BENCHMARK_CAPTURE(implicitStep, automatic, ImplicitSolver::Automatic, CholeskyBackend::Automatic)
    ->Name("ours/implicit_step")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);
BENCHMARK_CAPTURE(implicitStep, cholmod, ImplicitSolver::Cholesky, CholeskyBackend::Cholmod)
    ->Name("ours/implicit_step_cholmod")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);
BENCHMARK_CAPTURE(implicitStep, simplicial, ImplicitSolver::Cholesky,
                  CholeskyBackend::SimplicialLDLT)
    ->Name("baseline/implicit_step")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// A step after the first, weights rebuilt from the positions: the pattern is analysed already, so
// this is L and M rebuilt, M - tau L filled and refactorised, x, y, z solved. Timed between the
// progress callbacks of steps 2..6 of one run.
void laterStep(benchmark::State& state) {
  const Fixture& f = fixture();
  MeshSmoothingParameters p;
  p.time_step = f.tau;
  p.iterations = 6;
  // L and M rebuilt every step: the most work a later step can take (the README's figures); by
  // Cholesky, which the automatic choice would leave for conjugate gradients on so short a run.
  p.weight_update = WeightUpdate::EveryIteration;
  p.implicit_solver = ImplicitSolver::Cholesky;
  std::vector<std::chrono::steady_clock::time_point> step_ends;
  step_ends.reserve(p.iterations);
  for (auto _ : state) {
    step_ends.clear();
    const Eigen::Matrix3Xd x = smoothMeshPositions(
        f.topology, f.mesh.points, p, nullptr,
        [&](int, int) { step_ends.push_back(std::chrono::steady_clock::now()); });
    benchmark::DoNotOptimize(x.data());
    const std::chrono::duration<double> later = step_ends.back() - step_ends.front();
    state.SetIterationTime(later.count() / static_cast<double>(step_ends.size() - 1));
  }
}
BENCHMARK(laterStep)
    ->Name("ours/later_step")
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1);

// The first factorisation of a smoothing run: ordering, symbolic analysis and the numeric
// factorisation, by a new solver each time (its factor is allocated and faulted in afresh), with
// CHOLMOD and with Eigen's SimplicialLDLT (the solver of libigl's smoothing tutorial).
void firstFactorisation(benchmark::State& state, CholeskyBackend backend) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    SparseCholesky solver(backend);
    solver.compute(f.system);
  }
}
BENCHMARK_CAPTURE(firstFactorisation, cholmod, CholeskyBackend::Cholmod)
    ->Name("ours/first_factorisation")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
BENCHMARK_CAPTURE(firstFactorisation, simplicial, CholeskyBackend::SimplicialLDLT)
    ->Name("baseline/first_factorisation")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// A later factorisation: the symbolic analysis reused, against analysing again.
void refactorise(benchmark::State& state, bool reuse_pattern) {
  const Fixture& f = fixture();
  SparseCholesky solver(CholeskyBackend::Cholmod);
  // Outside the timing: the first factorisation also allocates the factor and BLAS buffers.
  solver.compute(f.system);
  for (auto _ : state) {
    if (reuse_pattern) {
      solver.factorize(f.system);
    } else {
      solver.compute(f.system);
    }
  }
}
BENCHMARK_CAPTURE(refactorise, reused, true)
    ->Name("ours/cholmod_factorisation")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
BENCHMARK_CAPTURE(refactorise, analysed_again, false)
    ->Name("baseline/cholmod_factorisation")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  pcl_ddg::tuneCholmodForLargeSystems();  // as the tools do
  pcl_ddg::bench::addRatio("ours/later_step", "ours/implicit_step");
  return pcl_ddg::bench::runWithRatios(argc, argv);
}
