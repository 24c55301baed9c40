#pragma once
// What PCANormalEstimation and QuadricNormalEstimation share: a pcl::Feature that, for every
// query point, gathers its neighbours (from whatever search method is set: a kd-tree, or
// MeshRingSearch for topological neighbourhoods) in double relative to the query point, fits
// something to them, and orients the resulting normal.
//
// Orientation (see normal_orientation.h): by the viewpoint, as PCL does, unless the search method
// is a MeshRingSearch (or setOrientationMesh was called), in which case by the mesh's faces.
// setViewPoint chooses the viewpoint explicitly.
//
// A point that cannot be estimated (non-finite, or too few finite neighbours) gets NaN output
// and output.is_dense = false; compute() counts them (getFailedPoints) and warns once.
#include <pcl/features/feature.h>

#include <Eigen/Core>
#include <cstdint>
#include <memory>

#include "pcl_ddg/features/normal_orientation.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {

template <typename PointInT, typename PointOutT>
class LocalFitEstimation : public pcl::Feature<PointInT, PointOutT> {
 public:
  using PointCloudOut = typename pcl::Feature<PointInT, PointOutT>::PointCloudOut;

  /** Orients normals towards this point (PCL's semantics; the default viewpoint is the origin). */
  void setViewPoint(float vx, float vy, float vz) {
    viewpoint_ = Eigen::Vector3d(vx, vy, vz);
    orientation_ = NormalOrientation::Viewpoint;
    orientation_chosen_ = true;
  }
  void getViewPoint(float& vx, float& vy, float& vz) const {
    vx = static_cast<float>(viewpoint_.x());
    vy = static_cast<float>(viewpoint_.y());
    vz = static_cast<float>(viewpoint_.z());
  }
  /** Orients normals like the faces of this mesh (its vertices are the input cloud's points). */
  void setOrientationMesh(std::shared_ptr<const MeshTopology> topology) {
    orientation_mesh_ = std::move(topology);
    orientation_ = NormalOrientation::MeshFaces;
    orientation_chosen_ = true;
  }
  /** The orientation used by the last compute(). */
  NormalOrientation getOrientation() const { return used_orientation_; }

  /** With setRadiusSearch: at most this many neighbours, the nearest (Open3D's hybrid search);
   *  0 (the default, PCL's semantics) takes every point in the radius, which on dense or
   *  duplicated scans can be thousands per query. */
  void setRadiusSearchMaxNeighbours(unsigned int max_neighbours) {
    max_neighbours_ = max_neighbours;
  }
  unsigned int getRadiusSearchMaxNeighbours() const { return max_neighbours_; }

  /** Threads for compute(); 0 = as many as the machine has. */
  void setNumberOfThreads(unsigned int threads) { threads_ = threads; }

  /** Points given NaN output by the last compute(). */
  std::int64_t getFailedPoints() const { return failed_points_; }

 protected:
  /** What a fit made of one neighbourhood. */
  enum class FitOutcome { Fitted, FellBack, Failed };

  bool initCompute() override;

  /** Runs fit(neighbours, count, query_index, query_position, output_index) -> FitOutcome for
   *  every query point, in parallel; neighbours holds the first count finite neighbours minus the
   *  query position. A Failed point's output is set invalid here. */
  template <typename Fit>
  void fitEachNeighbourhood(PointCloudOut& output, Fit&& fit);

  /** Turns n to agree with the reference of query point index (at position p); true if flipped. */
  bool orient(Eigen::Vector3d& n, pcl::index_t index, const Eigen::Vector3d& p) const;

  /** Sets every field of a point that cannot be estimated to NaN. */
  virtual void setInvalid(PointOutT& point) const = 0;

  unsigned int max_neighbours_ = 0;
  std::int64_t fallback_points_ = 0;  ///< counted by fitEachNeighbourhood (FitOutcome::FellBack)

 private:
  Eigen::Vector3d viewpoint_ = Eigen::Vector3d::Zero();
  NormalOrientation orientation_ = NormalOrientation::Viewpoint;
  bool orientation_chosen_ = false;  ///< false: by the search method (see above)
  NormalOrientation used_orientation_ = NormalOrientation::Viewpoint;
  std::shared_ptr<const MeshTopology> orientation_mesh_;
  Eigen::Matrix3Xd reference_normals_;  ///< MeshFaces: one per input point
  unsigned int threads_ = 0;
  std::int64_t failed_points_ = 0;
};

}  // namespace pcl_ddg

#include "pcl_ddg/features/impl/local_fit_estimation.hpp"
