#pragma once
/** \file
 * How LocalFitEstimation orients its normals (normal_orientation.h): the chosen policy, its
 * reference (the viewpoint, up, the mesh's face normals) and the spanning tree. It depends on the
 * input point type only, so it is compiled once per input type (src/features/fit_orientation.cpp)
 * rather than for each of PCL's 6 output types.
 */
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/search.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>

#include "pcl_ddg/features/consistent_orientation.h"
#include "pcl_ddg/features/normal_orientation.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {
namespace detail {

template <typename PointInT>
class FitOrientation {
 public:
  using Search = pcl::search::Search<PointInT>;
  using Cloud = pcl::PointCloud<PointInT>;

  // The choice, set by LocalFitEstimation's setters.
  NormalOrientation policy = NormalOrientation::Viewpoint;
  bool chosen = false;           ///< false: Viewpoint if viewpoint_given, else by the search method
  bool viewpoint_given = false;  ///< setViewPoint or useSensorOriginAsViewPoint was called
  std::optional<Eigen::Vector3d> up;
  std::shared_ptr<const MeshTopology> mesh;  ///< MeshFaces' mesh (a MeshRingSearch's if unset)
  int tree_neighbours = 10;
  typename Search::Ptr tree_graph;  ///< null: the search method
  bool seed_facing_viewpoint = false;

  /** Before a compute: fixes the policy (search: the estimator's search method), builds its
   *  reference and checks it fits the input; false, with a PCL_ERROR naming estimator, if not.
   *  positions: the input's exact coordinates (null: its floats). */
  bool prepare(const typename Cloud::ConstPtr& input, const Eigen::Matrix3Xd* positions,
               bool separate_surface, const typename Search::Ptr& search,
               const Eigen::Vector3d& viewpoint, const std::string& estimator);

  /** Turns n to agree with the reference of input point index (at position p); true if flipped.
   *  SpanningTree: towards the viewpoint, until makeConsistent. */
  bool orient(Eigen::Vector3d& n, pcl::index_t index, const Eigen::Vector3d& p) const;

  /** SpanningTree only (else nothing): turns normals (one per query point, in their order)
   *  consistently along a minimum spanning tree over each query point's tree_neighbours nearest
   *  from tree_graph or search; only the query points join the graph. */
  void makeConsistent(const Search& search, const Cloud& input, const pcl::Indices& indices,
                      int threads, pcl::PointCloud<pcl::Normal>& normals);

  /** The policy of the last prepare. */
  NormalOrientation used() const { return used_; }
  /** SpanningTree: what the last makeConsistent turned. */
  const ConsistentOrientationReport& report() const { return report_; }

 private:
  NormalOrientation used_ = NormalOrientation::Viewpoint;
  Eigen::Vector3d viewpoint_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3Xd reference_normals_;  ///< MeshFaces: one per input point
  ConsistentOrientationReport report_;
};

}  // namespace detail
}  // namespace pcl_ddg

#include "pcl_ddg/features/impl/fit_orientation.hpp"

#ifndef PCL_NO_PRECOMPILE
#include <boost/preprocessor/seq/for_each.hpp>
#define PCL_DDG_FIT_ORIENTATION(r, qualifier, T) \
  qualifier template class pcl_ddg::detail::FitOrientation<T>;
// Compiled in the library for PCL's input types (as PCL's own estimators are).
BOOST_PP_SEQ_FOR_EACH(PCL_DDG_FIT_ORIENTATION, extern, PCL_XYZ_POINT_TYPES)
#endif
