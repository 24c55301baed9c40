#pragma once
/** \file
 * What PCANormalEstimation, QuadricNormalEstimation and RobustNormalEstimation share: a
 * pcl::Feature that, for every query point, gathers its neighbours (from whatever search method is
 * set: a kd-tree, or MeshRingSearch for topological neighbourhoods) in double relative to the
 * query point, fits something to them, and orients the resulting normal.
 *
 * The interface of pcl::NormalEstimationOMP, so any of the three estimators replaces it (or
 * pcl::NormalEstimation) in existing code: computePointNormal (both overloads), the viewpoint
 * setters and the protected vpx_, vpy_, vpz_, a constructor taking the number of threads and
 * setNumberOfThreads (0: every core; the default here, where PCL's NormalEstimation uses one),
 * Ptr / ConstPtr of the class itself. See docs/pcl-drop-in.md for what differs.
 *
 * Orientation (see normal_orientation.h): by the viewpoint, as PCL does, unless the search method
 * is a MeshRingSearch (or setOrientationMesh was called), in which case by the mesh's faces.
 * The viewpoint is the input cloud's sensor_origin_, copied when the cloud is set, as in
 * pcl::NormalEstimation, unless setViewPoint chooses one. Setters only store, as PCL's: the
 * policy is fixed at compute(), whatever the order they were called in: the one a setOrientation*
 * chose, else Viewpoint if setViewPoint or useSensorOriginAsViewPoint was called, else by the
 * search method. setOrientationSpanningTree makes the
 * normals consistent along a minimum spanning tree of each point's nearest neighbours from the
 * search method (mesh rings, pixel grid or kd-tree: the graph follows the neighbourhood), for
 * clouds without a single viewpoint; the quadric's curvatures change sign with their normals.
 *
 * The fits read each neighbourhood in double relative to its query point, from the input's
 * floats or, given setInputPositions, from the exact coordinates beside them.
 *
 * A point that cannot be estimated (non-finite, or too few finite neighbours) gets NaN output
 * and output.is_dense = false; compute() counts them (getFailedPoints) and warns once.
 */
#include <pcl/features/feature.h>

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>

#include "pcl_ddg/features/consistent_orientation.h"
#include "pcl_ddg/features/fit_orientation.h"
#include "pcl_ddg/features/neighbourhood_fits.h"
#include "pcl_ddg/features/normal_orientation.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {

template <typename PointInT, typename PointOutT>
class LocalFitEstimation : public pcl::Feature<PointInT, PointOutT> {
 public:
  using Ptr = std::shared_ptr<LocalFitEstimation<PointInT, PointOutT>>;
  using ConstPtr = std::shared_ptr<const LocalFitEstimation<PointInT, PointOutT>>;
  using PointCloudOut = typename pcl::Feature<PointInT, PointOutT>::PointCloudOut;
  using PointCloudConstPtr = typename pcl::Feature<PointInT, PointOutT>::PointCloudConstPtr;

  /** Sets the input; while the sensor origin is the viewpoint (the default), copies the cloud's
   *  sensor_origin_ into it, as pcl::NormalEstimation does. */
  void setInputCloud(const PointCloudConstPtr& cloud) override {
    pcl::Feature<PointInT, PointOutT>::setInputCloud(cloud);
    if (use_sensor_origin_) copySensorOrigin();
  }

  /** Orients normals towards this point (PCL's semantics), instead of the input cloud's
   *  sensor_origin_. */
  void setViewPoint(float vx, float vy, float vz) {
    vpx_ = vx;
    vpy_ = vy;
    vpz_ = vz;
    use_sensor_origin_ = false;
    orientation_.viewpoint_given = true;
  }
  /** The viewpoint: the one set, or the input cloud's sensor_origin_ (PCL's default; the origin
   *  before a cloud is set). */
  void getViewPoint(float& vx, float& vy, float& vz) const {
    vx = vpx_;
    vy = vpy_;
    vz = vpz_;
  }
  /** Orients normals towards the input cloud's sensor_origin_ (the default, as
   *  pcl::NormalEstimation's useSensorOriginAsViewPoint; undoes setViewPoint). */
  void useSensorOriginAsViewPoint() {
    use_sensor_origin_ = true;
    copySensorOrigin();
    orientation_.viewpoint_given = true;
  }

  /**
   * The least-squares plane of the finite points `indices` of cloud, as
   * pcl::NormalEstimation::computePointNormal: plane_parameters = (n, -n . c) with c their
   * centroid and n the unit eigenvector of the smallest eigenvalue of their covariance
   * \f$ C = \frac{1}{m} \sum_i (p_i - c)(p_i - c)^T \f$, curvature the surface variation
   * \f$ \lambda_0 / (\lambda_0 + \lambda_1 + \lambda_2) \f$. n is not oriented (its sign is the
   * solver's, as PCL's; pcl::flipNormalTowardsViewpoint turns it). Formed in double about the
   * centroid, so far from the origin it keeps the accuracy PCL's float sums lose.
   * \return false, with every output NaN, for fewer than 3 finite points or points on one line.
   */
  bool computePointNormal(const pcl::PointCloud<PointInT>& cloud, const pcl::Indices& indices,
                          Eigen::Vector4f& plane_parameters, float& curvature) const;
  /** The same plane's normal (nx, ny, nz) and surface variation. */
  bool computePointNormal(const pcl::PointCloud<PointInT>& cloud, const pcl::Indices& indices,
                          float& nx, float& ny, float& nz, float& curvature) const;

  /** Orients normals towards the viewpoint (setViewPoint's, else the sensor origin) whatever
   *  the search method or an earlier setOrientation* chose. */
  void setOrientationViewpoint() { choose(NormalOrientation::Viewpoint); }
  /** Orients normals up: n . up >= 0, up = (ux, uy, uz) (setUpDirection; default +z). */
  void setOrientationUp() { choose(NormalOrientation::Up); }
  /** The up direction of setOrientationUp, and the reference of a spanning tree not seeded
   *  facing the viewpoint (consistent_orientation.h). Unset: +z for Up, none for the tree. */
  void setUpDirection(float ux, float uy, float uz) {
    orientation_.up = Eigen::Vector3d(ux, uy, uz);
  }
  /** Orients normals like the faces of this mesh (its vertices are the input cloud's points). */
  void setOrientationMesh(std::shared_ptr<const MeshTopology> topology) {
    orientation_.mesh = std::move(topology);
    choose(NormalOrientation::MeshFaces);
  }
  /** Orients normals consistently along a minimum spanning tree over each point's `neighbours`
   *  nearest (consistent_orientation.h) from `graph` (a search over the same input; null: the
   *  search method); each tree is seeded facing the viewpoint (setViewPoint) if
   *  seed_facing_viewpoint, else by the up direction where it decides (setUpDirection), else up
   *  at its highest point. Only the points being estimated (the
   *  indices) join the graph. */
  void setOrientationSpanningTree(int neighbours = 10, bool seed_facing_viewpoint = false,
                                  typename pcl::search::Search<PointInT>::Ptr graph = nullptr) {
    orientation_.tree_neighbours = neighbours;
    orientation_.seed_facing_viewpoint = seed_facing_viewpoint;
    orientation_.tree_graph = std::move(graph);
    choose(NormalOrientation::SpanningTree);
  }
  /** SpanningTree: what the last compute() turned (after the per-point viewpoint sign). */
  const ConsistentOrientationReport& getOrientationReport() const { return orientation_.report(); }

  /** The orientation used by the last compute(). */
  NormalOrientation getOrientation() const { return orientation_.used(); }

  /** With setRadiusSearch: at most this many neighbours, the nearest (Open3D's hybrid search);
   *  0 (the default, PCL's semantics) takes every point in the radius, which on dense or
   *  duplicated scans can be thousands per query. */
  void setRadiusSearchMaxNeighbours(unsigned int max_neighbours) {
    max_neighbours_ = max_neighbours;
  }
  unsigned int getRadiusSearchMaxNeighbours() const { return max_neighbours_; }
  /** With setRadiusSearch: a ball holding fewer than this many points (the query included) is
   *  replaced by the min_neighbours nearest, so sparse parts of an uneven scan still get an
   *  estimate; 0 (the default, PCL's semantics) keeps the ball. */
  void setRadiusSearchMinNeighbours(unsigned int min_neighbours) {
    min_neighbours_ = min_neighbours;
  }
  unsigned int getRadiusSearchMinNeighbours() const { return min_neighbours_; }

  /** The input's coordinates in double, column i for point i: the fits read them instead of the
   *  input's floats, in which the search method still looks (local_cloud.h: a cloud whose exact
   *  coordinates are doubles, placed about a local origin). A neighbour is used where its
   *  position is finite (a point left out is NaN in both). Needs the search surface to be the
   *  input; null (the default): the floats. */
  void setInputPositions(std::shared_ptr<const Eigen::Matrix3Xd> positions) {
    input_positions_ = std::move(positions);
  }
  const std::shared_ptr<const Eigen::Matrix3Xd>& getInputPositions() const {
    return input_positions_;
  }

  /** Threads for compute(), as pcl::NormalEstimationOMP; 0 = as many as the machine has. */
  void setNumberOfThreads(unsigned int nr_threads = 0) { threads_ = nr_threads; }
  unsigned int getNumberOfThreads() const { return threads_; }

  /** Points given NaN output by the last compute(). */
  std::int64_t getFailedPoints() const { return failed_points_; }

 protected:
  using FitOutcome = detail::FitOutcome;

  bool initCompute() override;

  /** Runs fit for every query point, in parallel (detail::fitNeighbourhoods; the fit's
   *  arguments are detail::NeighbourhoodFit's). A Failed point's output is set invalid here. */
  void fitEachNeighbourhood(PointCloudOut& output, const detail::NeighbourhoodFit& fit);

  /** Turns n to agree with the reference of query point index (at position p); true if flipped.
   *  SpanningTree: towards the viewpoint, until makeOrientationConsistent. */
  bool orient(Eigen::Vector3d& n, pcl::index_t index, const Eigen::Vector3d& p) const {
    return orientation_.orient(n, index, p);
  }

  /** SpanningTree only: turns output normals to agree along the tree, calling
   *  on_turn(output_index) after each normal it turns. */
  template <typename OnTurn>
  void makeOrientationConsistent(PointCloudOut& output, OnTurn&& on_turn);

  /** Sets the normal and curvature of a point that cannot be estimated to NaN. */
  void setInvalid(PointOutT& point) const {
    point.normal_x = point.normal_y = point.normal_z = point.curvature =
        std::numeric_limits<float>::quiet_NaN();
  }

  /** The k of the last initCompute: pcl::Feature's k_, or defaultK() when neither setKSearch nor
   *  setRadiusSearch was called; 0 with a radius. */
  int searchK() const { return search_k_; }
  /** The k used when neither setKSearch nor setRadiusSearch was called; 0: none (PCL's
   *  "neither radius nor k set" error). Applied at each compute, never stored in k_, so that a
   *  later setRadiusSearch still works. */
  virtual int defaultK() const { return 0; }

  /** threads_, with 0 meaning every core. */
  int threadCount() const;

  /** Input point j in double: setInputPositions' column, else its float point. */
  Eigen::Vector3d inputPosition(pcl::index_t j) const {
    return input_positions_
               ? Eigen::Vector3d(input_positions_->col(j))
               : Eigen::Vector3d((*this->input_)[j].getVector3fMap().template cast<double>());
  }

  unsigned int max_neighbours_ = 0;
  unsigned int min_neighbours_ = 0;
  std::int64_t fallback_points_ = 0;  ///< counted by fitEachNeighbourhood (FitOutcome::FellBack)

  /** The viewpoint, named and kept as in pcl::NormalEstimation (protected there too). */
  float vpx_ = 0.0f, vpy_ = 0.0f, vpz_ = 0.0f;
  /** true: vpx_, vpy_, vpz_ follow the input cloud's sensor_origin_. */
  bool use_sensor_origin_ = true;
  /** Threads for compute() (0: every core), as pcl::NormalEstimationOMP's. */
  unsigned int threads_ = 0;

 private:
  /** The input's sensor origin into vpx_, vpy_, vpz_; the origin without an input. */
  void copySensorOrigin() {
    const Eigen::Vector4f origin =
        this->input_ ? this->input_->sensor_origin_ : Eigen::Vector4f::Zero();
    vpx_ = origin.x();
    vpy_ = origin.y();
    vpz_ = origin.z();
  }

  void choose(NormalOrientation policy) {
    orientation_.policy = policy;
    orientation_.chosen = true;
  }

  std::shared_ptr<const Eigen::Matrix3Xd> input_positions_;
  detail::FitOrientation<PointInT> orientation_;
  int search_k_ = 0;
  std::int64_t failed_points_ = 0;
};

}  // namespace pcl_ddg

#include "pcl_ddg/features/impl/local_fit_estimation.hpp"
