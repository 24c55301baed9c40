// One implicit cotangent smoothing step on a 1.15M-vertex torus, everything included (rebuilding
// L and M from the positions, assembling M - tau L, factorising, solving for x, y, z): with
// CHOLMOD's supernodal LLT and with Eigen's SimplicialLDLT. Then the factorisation alone, with the
// symbolic analysis reused (what every step after the first costs) and redone each time.
#include <benchmark/benchmark.h>

#include "bench_support.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
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

void implicitStep(benchmark::State& state, CholeskyBackend backend) {
  const Fixture& f = fixture();
  MeshSmoothingParameters p;
  p.time_step = f.tau;
  p.solver = backend;
  for (auto _ : state) {
    const Eigen::Matrix3Xd x = smoothMeshPositions(f.topology, f.mesh.points, p);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["vertices"] = static_cast<double>(f.mesh.points.cols());
}
BENCHMARK_CAPTURE(implicitStep, cholmod, CholeskyBackend::Cholmod)
    ->Name("ours/implicit_step")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);
BENCHMARK_CAPTURE(implicitStep, simplicial, CholeskyBackend::SimplicialLDLT)
    ->Name("baseline/implicit_step")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// Ten steps with the weights rebuilt every step: what a step costs once the pattern is analysed.
void tenSteps(benchmark::State& state) {
  const Fixture& f = fixture();
  MeshSmoothingParameters p;
  p.time_step = f.tau;
  p.iterations = 10;
  for (auto _ : state) {
    const Eigen::Matrix3Xd x = smoothMeshPositions(f.topology, f.mesh.points, p);
    benchmark::DoNotOptimize(x.data());
  }
}
BENCHMARK(tenSteps)
    ->Name("ours/ten_implicit_steps")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

void refactorise(benchmark::State& state, bool reuse_pattern) {
  const Fixture& f = fixture();
  SparseCholesky solver(CholeskyBackend::Cholmod);
  solver.analyzePattern(f.system);
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
  pcl_ddg::bench::addRatio("ours/ten_implicit_steps", "ours/implicit_step");
  return pcl_ddg::bench::runWithRatios(argc, argv);
}
