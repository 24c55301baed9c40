// Every parallel computation gives the same bits with 1, 2 and 8 OpenMP threads: no result may
// depend on how the work was split (no floating-point reductions across threads).
#include <gtest/gtest.h>
#include <omp.h>

#include <cstring>
#include <functional>
#include <vector>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/operators/laplacian.h"
#include "pcl_ddg/operators/mass_matrix.h"
#include "pcl_ddg/surface/mesh_normals.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace pcl_ddg {
namespace test {
namespace {

// The raw bytes of a result, so that NaNs compare equal to themselves and -0 differs from 0.
using Bytes = std::vector<unsigned char>;

template <typename Matrix>
Bytes bytesOf(const Matrix& m) {
  Bytes b(static_cast<std::size_t>(m.size()) * sizeof(typename Matrix::Scalar));
  if (!b.empty()) std::memcpy(b.data(), m.data(), b.size());
  return b;
}

Bytes bytesOf(const Eigen::SparseMatrix<double>& m) {
  Eigen::SparseMatrix<double> c = m;
  c.makeCompressed();
  return bytesOf(Eigen::Map<const Eigen::VectorXd>(c.valuePtr(), c.nonZeros()));
}

template <typename Point>
Bytes bytesOf(const pcl::PointCloud<Point>& cloud) {
  Bytes b(cloud.size() * sizeof(Point));
  if (!b.empty()) std::memcpy(b.data(), cloud.points.data(), b.size());
  return b;
}

void expectSameWithAnyThreadCount(const char* what, const std::function<Bytes()>& compute) {
  SCOPED_TRACE(what);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const Bytes reference = compute();
  ASSERT_FALSE(reference.empty());
  for (const int threads : {2, 8}) {
    omp_set_num_threads(threads);
    EXPECT_TRUE(compute() == reference) << threads << " threads";
  }
  omp_set_num_threads(saved);
}

// An irregular surface far from the origin: rounding differs from point to point.
SurfaceSample jitteredTorusFarAway() {
  Sampling sampling;
  sampling.resolution = 48;
  sampling.jitter = 0.2;
  SurfaceSample torus = makeTorus(sampling);
  torus.rotateAndShiftFar();
  return torus;
}

TEST(ThreadDeterminism, MeshOperatorsNormalsCurvaturesAndSmoothing) {
  const SurfaceSample torus = jitteredTorusFarAway();
  const MeshTopology topology = topologyOf(torus);
  const Eigen::Matrix3Xd& x = torus.points;

  for (const NormalWeighting weighting : {NormalWeighting::Uniform, NormalWeighting::Area,
                                          NormalWeighting::Angle, NormalWeighting::MeanCurvature}) {
    expectSameWithAnyThreadCount("normals", [&] {
      MeshNormalOptions options;
      options.weighting = weighting;
      return bytesOf(computeMeshNormals(topology, x, options).normals);
    });
  }
  expectSameWithAnyThreadCount("cotan Laplacian", [&] {
    return bytesOf(laplacian(topology, x, LaplacianWeights::Cotangent, LaplacianForm::Averaged));
  });
  expectSameWithAnyThreadCount(
      "mass", [&] { return bytesOf(lumpedMass(topology, x, MassType::MixedVoronoi)); });
  expectSameWithAnyThreadCount("curvatures", [&] {
    const VertexCurvatures c = computeCurvatures(topology, x);
    Eigen::MatrixXd all(c.mean_curvature.size(), 4);
    all << c.mean_curvature, c.gauss_curvature, c.k1, c.k2;
    return bytesOf(all);
  });
  for (const SmoothingScheme scheme : {SmoothingScheme::Explicit, SmoothingScheme::Implicit}) {
    expectSameWithAnyThreadCount("smoothing", [&] {
      MeshSmoothingParameters p;
      p.scheme = scheme;
      p.time_step = 0.5 * explicitStabilityLimit(topology, x);
      p.iterations = 3;
      return bytesOf(smoothMeshPositions(topology, x, p));
    });
  }
}

TEST(ThreadDeterminism, FittedNormalsAndCurvaturesWithBothNeighbourhoods) {
  const SurfaceSample torus = jitteredTorusFarAway();
  const auto cloud = toCloud(torus.points);
  const auto topology = topologyPtrOf(torus);
  for (const LocalFitMethod method : {LocalFitMethod::PCA, LocalFitMethod::Quadric}) {
    for (const NeighbourhoodKind kind : {NeighbourhoodKind::MeshRings, NeighbourhoodKind::KdTree}) {
      expectSameWithAnyThreadCount("local fits", [&] {
        LocalFitOptions options;
        options.method = method;
        options.neighbourhood = kind;
        options.k = 16;
        options.threads = static_cast<unsigned int>(omp_get_max_threads());
        const LocalFitResult r = fitLocalSurfaces(cloud, topology, options);
        Bytes b = bytesOf(r.normals);
        const Bytes c = bytesOf(r.curvatures);
        b.insert(b.end(), c.begin(), c.end());
        return b;
      });
    }
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
