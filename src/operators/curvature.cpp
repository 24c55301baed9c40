#include "pcl_ddg/operators/curvature.h"

#include <cmath>
#include <limits>

#include "pcl_ddg/operators/laplacian.h"
#include "pcl_ddg/operators/triangle_quantities.h"

namespace pcl_ddg {
namespace {

constexpr double kPi = 3.14159265358979323846;

int cornerOf(const Eigen::Matrix3Xi& tris, int t, int v) {
  return tris(0, t) == v ? 0 : (tris(1, t) == v ? 1 : 2);
}

Eigen::VectorXd angleDefect(const MeshTopology& topology, const TriangleQuantities& q) {
  const Eigen::Matrix3Xi& tris = topology.triangles();
  Eigen::VectorXd defect(topology.numVertices());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    if (topology.isIsolated(v)) {
      defect[v] = 0.0;
      continue;
    }
    double angle_sum = 0.0;
    for (const int t : topology.incidentTriangles(v)) angle_sum += q.angles(cornerOf(tris, t, v), t);
    defect[v] = (topology.isBoundary(v) ? kPi : 2.0 * kPi) - angle_sum;
  }
  return defect;
}

// -1/2 M^-1 L x from the summed cotangent Laplacian and the masses.
Eigen::Matrix3Xd meanCurvatureNormal(const Eigen::SparseMatrix<double>& cotan_laplacian,
                                     const Eigen::VectorXd& mass,
                                     const Eigen::Matrix3Xd& positions) {
  // L is symmetric, so (L x^T)^T = x L.
  Eigen::Matrix3Xd hn = -0.5 * (positions * cotan_laplacian);
  for (Eigen::Index v = 0; v < hn.cols(); ++v) {
    hn.col(v) = mass[v] > 0.0 ? Eigen::Vector3d(hn.col(v) / mass[v]) : Eigen::Vector3d::Zero();
  }
  return hn;
}

// Area-weighted vertex normals (unnormalised): the orientation reference for H.
Eigen::Matrix3Xd areaNormals(const MeshTopology& topology, const TriangleQuantities& q) {
  Eigen::Matrix3Xd n(3, topology.numVertices());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const int t : topology.incidentTriangles(v)) sum += q.area_vectors.col(t);
    n.col(v) = sum;
  }
  return n;
}

}  // namespace

Eigen::VectorXd angleDefect(const MeshTopology& topology, const Eigen::Matrix3Xd& positions) {
  return angleDefect(topology, computeTriangleQuantities(topology, positions));
}

Eigen::Matrix3Xd meanCurvatureNormal(const MeshTopology& topology, const Eigen::Matrix3Xd& positions,
                                     MassType mass) {
  const TriangleQuantities q = computeTriangleQuantities(topology, positions);
  return meanCurvatureNormal(cotangentLaplacian(topology, q),
                             lumpedMass(topology, positions, q, mass), positions);
}

VertexCurvatures computeCurvatures(const MeshTopology& topology, const Eigen::Matrix3Xd& positions,
                                   MassType mass) {
  const TriangleQuantities q = computeTriangleQuantities(topology, positions);
  VertexCurvatures c;
  c.vertex_area = lumpedMass(topology, positions, q, mass);
  const Eigen::VectorXd defect = angleDefect(topology, q);
  const Eigen::Matrix3Xd hn =
      meanCurvatureNormal(cotangentLaplacian(topology, q), c.vertex_area, positions);
  const Eigen::Matrix3Xd reference = areaNormals(topology, q);

  const int n = topology.numVertices();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.mean.resize(n);
  c.gauss.resize(n);
  c.kappa1.resize(n);
  c.kappa2.resize(n);
  c.valid.assign(n, 0);
  std::int64_t clamped = 0, invalid = 0;
#pragma omp parallel for schedule(static) reduction(+ : clamped, invalid)
  for (int v = 0; v < n; ++v) {
    const double area = c.vertex_area[v];
    if (!(area > 0.0)) {
      c.mean[v] = c.gauss[v] = c.kappa1[v] = c.kappa2[v] = nan;
      ++invalid;
      continue;
    }
    c.valid[v] = 1;
    const double h = hn.col(v).norm();
    c.mean[v] = hn.col(v).dot(reference.col(v)) < 0.0 ? -h : h;
    c.gauss[v] = defect[v] / area;
    const double discriminant = c.mean[v] * c.mean[v] - c.gauss[v];
    if (discriminant < 0.0) ++clamped;
    const double root = std::sqrt(std::max(discriminant, 0.0));
    c.kappa1[v] = c.mean[v] + root;
    c.kappa2[v] = c.mean[v] - root;
  }
  c.clamped_vertices = clamped;
  c.invalid_vertices = invalid;
  return c;
}

}  // namespace pcl_ddg
