#include "estimator_support.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "test_data.h"

namespace pcl_ddg {
namespace test {

pcl::PointCloud<pcl::PointXYZ>::Ptr toCloud(const Eigen::Matrix3Xd& points) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(points.cols());
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    (*cloud)[i].getVector3fMap() = points.col(i).cast<float>();
  }
  cloud->width = static_cast<std::uint32_t>(points.cols());
  cloud->height = 1;
  cloud->is_dense = points.allFinite();
  return cloud;
}

MeshTopology topologyOf(const SurfaceSample& surface) {
  return MeshTopology(static_cast<int>(surface.points.cols()), surface.triangles);
}

pcl::PolygonMesh polygonMeshOf(const SurfaceSample& surface) {
  std::vector<std::vector<int>> faces;
  faces.reserve(surface.triangles.cols());
  for (Eigen::Index t = 0; t < surface.triangles.cols(); ++t) {
    faces.push_back({surface.triangles(0, t), surface.triangles(1, t), surface.triangles(2, t)});
  }
  return makeMesh(surface.points, faces);
}

std::shared_ptr<const MeshTopology> topologyPtrOf(const SurfaceSample& surface) {
  return std::make_shared<const MeshTopology>(static_cast<int>(surface.points.cols()),
                                              surface.triangles);
}

SurfaceSample makeTwoSheets(double gap) {
  const SurfaceSample top = makePlane({24, 0.1, 1});
  const SurfaceSample bottom = makePlane({24, 0.1, 2});
  const Eigen::Index n = top.points.cols();
  SurfaceSample s;
  s.points.resize(3, 2 * n);
  s.points << top.points, bottom.points.colwise() - Eigen::Vector3d(0, 0, gap);
  s.normals.resize(3, 2 * n);
  s.normals << top.normals, -bottom.normals;
  // The bottom plate faces down: its triangles are wound the other way.
  Eigen::Matrix3Xi flipped = bottom.triangles;
  flipped.row(1).swap(flipped.row(2));
  s.triangles.resize(3, 2 * top.triangles.cols());
  s.triangles << top.triangles, flipped.array() + static_cast<int>(n);
  return s;
}

Eigen::Matrix3Xd normalsOf(const pcl::PointCloud<pcl::Normal>& normals) {
  Eigen::Matrix3Xd n(3, normals.size());
  for (std::size_t i = 0; i < normals.size(); ++i)
    n.col(i) = normals[i].getNormalVector3fMap().cast<double>();
  return n;
}

AngleErrors angleErrors(const Eigen::Matrix3Xd& estimated, const Eigen::Matrix3Xd& truth,
                        SignMode mode) {
  AngleErrors e;
  int counted = 0;
  for (Eigen::Index i = 0; i < estimated.cols(); ++i) {
    if (!estimated.col(i).allFinite()) {
      ++e.invalid;
      continue;
    }
    const Eigen::Vector3d n = estimated.col(i).normalized();
    double cosine = n.dot(truth.col(i));
    if (mode == SignMode::Unsigned) cosine = std::abs(cosine);
    // atan2 of sine and cosine keeps small angles accurate.
    const double angle = std::atan2(n.cross(truth.col(i)).norm(), cosine) * 180.0 / M_PI;
    e.mean += angle;
    e.max = std::max(e.max, angle);
    ++counted;
  }
  if (counted > 0) e.mean /= counted;
  return e;
}

double observedOrder(double error_coarse, double error_fine, double h_coarse, double h_fine) {
  return std::log(error_coarse / error_fine) / std::log(h_coarse / h_fine);
}

Eigen::Vector3d bruteForcePcaNormal(const Eigen::Matrix3Xd& points, Eigen::Index i, int k) {
  std::vector<std::pair<long double, Eigen::Index>> d(static_cast<std::size_t>(points.cols()));
  for (Eigen::Index j = 0; j < points.cols(); ++j) {
    long double s = 0.0L;
    for (int c = 0; c < 3; ++c) {
      const long double e = static_cast<long double>(points(c, j)) - points(c, i);
      s += e * e;
    }
    d[static_cast<std::size_t>(j)] = {s, j};
  }
  std::partial_sort(d.begin(), d.begin() + k, d.end());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int n = 0; n < k; ++n) mean += points.col(d[n].second) - points.col(i);
  mean /= k;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int n = 0; n < k; ++n) {
    const Eigen::Vector3d e = points.col(d[n].second) - points.col(i) - mean;
    covariance += e * e.transpose();
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvectors().col(0);
}

}  // namespace test
}  // namespace pcl_ddg
