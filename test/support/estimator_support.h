#pragma once
// Glue between the analytic surfaces and PCL's estimator API: clouds, searches, angle errors.
#include <pcl/PolygonMesh.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <memory>

#include "analytic_surfaces.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {
namespace test {

pcl::PointCloud<pcl::PointXYZ>::Ptr toCloud(const Eigen::Matrix3Xd& points);

MeshTopology topologyOf(const SurfaceSample& surface);
std::shared_ptr<const MeshTopology> topologyPtrOf(const SurfaceSample& surface);

/** The sampled mesh as a PCL mesh (float x, y, z; its triangles as polygons), e.g. to save it. */
pcl::PolygonMesh polygonMeshOf(const SurfaceSample& surface);

/** A thin two-sheet surface: two jittered 24 x 24 plates over [-1,1]^2 (h = 1/12), the top one
 *  facing +z, the bottom one gap below it facing -z, as one mesh of two components. */
SurfaceSample makeTwoSheets(double gap);

/** Normals of a PCL cloud as a 3 x N double matrix (NaN kept). */
Eigen::Matrix3Xd normalsOf(const pcl::PointCloud<pcl::Normal>& normals);

struct AngleErrors {
  double mean = 0.0, max = 0.0;  ///< degrees
  int invalid = 0;               ///< non-finite estimates (excluded from mean and max)
};

/** Angles between estimates and truth; Unsigned compares lines (up to sign). */
enum class SignMode { Signed, Unsigned };
AngleErrors angleErrors(const Eigen::Matrix3Xd& estimated, const Eigen::Matrix3Xd& truth,
                        SignMode mode);

/** log(e_coarse / e_fine) / log(h_coarse / h_fine). */
/** An oracle independent of the library: point i's k nearest (itself included) by brute force in
 *  long double on the coordinates given, their covariance about their mean in double, and Eigen's
 *  eigenvector of its smallest eigenvalue (unoriented). */
Eigen::Vector3d bruteForcePcaNormal(const Eigen::Matrix3Xd& points, Eigen::Index i, int k);

double observedOrder(double error_coarse, double error_fine, double h_coarse, double h_fine);

}  // namespace test
}  // namespace pcl_ddg
