// Mesh operators on a 1.15M-vertex torus (2.3M triangles), each next to the textbook baseline:
// triplet-list assembly with setFromTriplets for L (and the mean-curvature normals built on it),
// serial face-loop scatter for the other normals and the masses.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <cmath>
#include <vector>

#include "bench_support.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/operators/laplacian.h"
#include "pcl_ddg/operators/mass_matrix.h"
#include "pcl_ddg/surface/mesh_normals.h"

namespace pcl_ddg {
namespace bench {
namespace {

constexpr int kAround = 1536, kTube = 750;  // 1,152,000 vertices, 2,304,000 triangles

struct Fixture {
  const BenchMesh& mesh = torusMesh(kAround, kTube);
  MeshTopology topology{static_cast<int>(mesh.points.cols()), mesh.triangles};
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

// ---- baselines -------------------------------------------------------------------------------

// Face-loop scatter: each face adds its weighted normal to its three corners.
Eigen::Matrix3Xd baselineFaceNormals(const BenchMesh& m, NormalWeighting weighting) {
  Eigen::Matrix3Xd n = Eigen::Matrix3Xd::Zero(3, m.points.cols());
  for (Eigen::Index t = 0; t < m.triangles.cols(); ++t) {
    Eigen::Vector3d p[3];
    for (int k = 0; k < 3; ++k) p[k] = m.points.col(m.triangles(k, t));
    const Eigen::Vector3d cross = (p[1] - p[0]).cross(p[2] - p[0]);
    for (int k = 0; k < 3; ++k) {
      double weight = 1.0;  // area weighting: the cross product is twice the area
      if (weighting == NormalWeighting::Uniform) weight = 1.0 / cross.norm();
      if (weighting == NormalWeighting::Angle) {
        const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
        weight = std::atan2(u.cross(v).norm(), u.dot(v)) / cross.norm();
      }
      n.col(m.triangles(k, t)) += weight * cross;
    }
  }
  n.colwise().normalize();
  return n;
}

double cotangent(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  return u.dot(v) / u.cross(v).norm();
}

Eigen::SparseMatrix<double> baselineCotanLaplacian(const BenchMesh& m) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(12 * static_cast<std::size_t>(m.triangles.cols()));
  for (Eigen::Index t = 0; t < m.triangles.cols(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int i = m.triangles((k + 1) % 3, t), j = m.triangles((k + 2) % 3, t);
      const int o = m.triangles(k, t);
      const double w =
          0.5 * cotangent(m.points.col(i) - m.points.col(o), m.points.col(j) - m.points.col(o));
      triplets.emplace_back(i, j, w);
      triplets.emplace_back(j, i, w);
      triplets.emplace_back(i, i, -w);
      triplets.emplace_back(j, j, -w);
    }
  }
  Eigen::SparseMatrix<double> l(m.points.cols(), m.points.cols());
  l.setFromTriplets(triplets.begin(), triplets.end());
  return l;
}

Eigen::VectorXd baselineMixedMass(const BenchMesh& m) {
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(m.points.cols());
  for (Eigen::Index t = 0; t < m.triangles.cols(); ++t) {
    Eigen::Vector3d p[3];
    for (int k = 0; k < 3; ++k) p[k] = m.points.col(m.triangles(k, t));
    const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    double cot[3];
    for (int k = 0; k < 3; ++k) cot[k] = cotangent(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
    for (int k = 0; k < 3; ++k) {
      double a;
      if (cot[k] < 0) {
        a = area / 2;
      } else if (cot[(k + 1) % 3] < 0 || cot[(k + 2) % 3] < 0) {
        a = area / 4;
      } else {
        a = ((p[(k + 1) % 3] - p[k]).squaredNorm() * cot[(k + 2) % 3] +
             (p[(k + 2) % 3] - p[k]).squaredNorm() * cot[(k + 1) % 3]) /
            8;
      }
      mass[m.triangles(k, t)] += a;
    }
  }
  return mass;
}

// -M^-1 L x from the triplet-assembled L, oriented like the area normal.
Eigen::Matrix3Xd baselineMeanCurvatureNormals(const BenchMesh& m) {
  const Eigen::SparseMatrix<double> l = baselineCotanLaplacian(m);
  const Eigen::VectorXd mass = baselineMixedMass(m);
  const Eigen::Matrix3Xd area_normals = baselineFaceNormals(m, NormalWeighting::Area);
  Eigen::Matrix3Xd n = -(l * m.points.transpose()).transpose();
  for (Eigen::Index v = 0; v < n.cols(); ++v) {
    n.col(v) /= mass[v];
    if (n.col(v).dot(area_normals.col(v)) < 0) n.col(v) = -n.col(v);
  }
  n.colwise().normalize();
  return n;
}

// ---- benchmarks ------------------------------------------------------------------------------

void setCounters(benchmark::State& state) {
  state.counters["vertices"] = static_cast<double>(fixture().mesh.points.cols());
}

void normals(benchmark::State& state, NormalWeighting weighting) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        computeMeshNormals(f.topology, f.mesh.points, {weighting}).normals.data());
  }
  setCounters(state);
}
BENCHMARK_CAPTURE(normals, ours / area_normals, NormalWeighting::Area)
    ->Name("ours/area_normals")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(normals, ours / uniform_normals, NormalWeighting::Uniform)
    ->Name("ours/uniform_normals")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(normals, ours / angle_normals, NormalWeighting::Angle)
    ->Name("ours/angle_normals")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(normals, ours / mean_curvature_normals, NormalWeighting::MeanCurvature)
    ->Name("ours/mean_curvature_normals")
    ->Unit(benchmark::kMillisecond);

void baselineNormals(benchmark::State& state, NormalWeighting weighting) {
  for (auto _ : state)
    benchmark::DoNotOptimize(baselineFaceNormals(fixture().mesh, weighting).data());
  setCounters(state);
}
BENCHMARK_CAPTURE(baselineNormals, area, NormalWeighting::Area)
    ->Name("baseline/area_normals")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(baselineNormals, uniform, NormalWeighting::Uniform)
    ->Name("baseline/uniform_normals")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(baselineNormals, angle, NormalWeighting::Angle)
    ->Name("baseline/angle_normals")
    ->Unit(benchmark::kMillisecond);

void baselineMeanCurvatureNormalsBench(benchmark::State& state) {
  for (auto _ : state)
    benchmark::DoNotOptimize(baselineMeanCurvatureNormals(fixture().mesh).data());
  setCounters(state);
}
BENCHMARK(baselineMeanCurvatureNormalsBench)
    ->Name("baseline/mean_curvature_normals")
    ->Unit(benchmark::kMillisecond);

void cotanLaplacian(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(laplacian(f.topology, f.mesh.points).valuePtr());
  setCounters(state);
}
BENCHMARK(cotanLaplacian)->Name("ours/cotan_laplacian")->Unit(benchmark::kMillisecond);

void baselineLaplacian(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(baselineCotanLaplacian(fixture().mesh).valuePtr());
  setCounters(state);
}
BENCHMARK(baselineLaplacian)->Name("baseline/cotan_laplacian")->Unit(benchmark::kMillisecond);

void mixedMass(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(lumpedMass(f.topology, f.mesh.points).data());
  setCounters(state);
}
BENCHMARK(mixedMass)->Name("ours/mixed_mass")->Unit(benchmark::kMillisecond);

void baselineMass(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(baselineMixedMass(fixture().mesh).data());
  setCounters(state);
}
BENCHMARK(baselineMass)->Name("baseline/mixed_mass")->Unit(benchmark::kMillisecond);

void laplacianAndMass(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    benchmark::DoNotOptimize(laplacian(f.topology, f.mesh.points).valuePtr());
    benchmark::DoNotOptimize(lumpedMass(f.topology, f.mesh.points).data());
  }
  setCounters(state);
}
BENCHMARK(laplacianAndMass)->Name("ours/cotan_laplacian+mixed_mass")->Unit(benchmark::kMillisecond);

void baselineLaplacianAndMass(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(baselineCotanLaplacian(fixture().mesh).valuePtr());
    benchmark::DoNotOptimize(baselineMixedMass(fixture().mesh).data());
  }
  setCounters(state);
}
BENCHMARK(baselineLaplacianAndMass)
    ->Name("baseline/cotan_laplacian+mixed_mass")
    ->Unit(benchmark::kMillisecond);

void curvatures(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state)
    benchmark::DoNotOptimize(computeCurvatures(f.topology, f.mesh.points).mean_curvature.data());
  setCounters(state);
}
BENCHMARK(curvatures)->Name("ours/all_curvatures")->Unit(benchmark::kMillisecond);

void baselineCurvatures(benchmark::State& state) {
  const BenchMesh& m = fixture().mesh;
  for (auto _ : state) {
    const Eigen::SparseMatrix<double> l = baselineCotanLaplacian(m);
    const Eigen::VectorXd mass = baselineMixedMass(m);
    const Eigen::Matrix3Xd hn = -0.5 * (l * m.points.transpose()).transpose();
    Eigen::VectorXd angle_sum = Eigen::VectorXd::Zero(m.points.cols());
    for (Eigen::Index t = 0; t < m.triangles.cols(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d o = m.points.col(m.triangles(k, t));
        const Eigen::Vector3d u = m.points.col(m.triangles((k + 1) % 3, t)) - o;
        const Eigen::Vector3d v = m.points.col(m.triangles((k + 2) % 3, t)) - o;
        angle_sum[m.triangles(k, t)] += std::atan2(u.cross(v).norm(), u.dot(v));
      }
    }
    const Eigen::VectorXd h = hn.colwise().norm().transpose().cwiseQuotient(2 * mass);
    const Eigen::VectorXd k =
        (2 * 3.14159265358979323846 - angle_sum.array()).matrix().cwiseQuotient(mass);
    const Eigen::VectorXd root = (h.array().square() - k.array()).max(0.0).sqrt().matrix();
    const Eigen::VectorXd kappa1 = h + root, kappa2 = h - root;
    benchmark::DoNotOptimize(kappa1.data());
    benchmark::DoNotOptimize(kappa2.data());
  }
  setCounters(state);
}
BENCHMARK(baselineCurvatures)->Name("baseline/all_curvatures")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  return pcl_ddg::bench::runWithRatios(argc, argv);
}
