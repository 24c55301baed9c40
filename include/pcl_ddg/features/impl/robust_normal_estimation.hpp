#pragma once
#include <pcl/common/point_tests.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <utility>

#include "pcl_ddg/features/robust_normal_estimation.h"
#include "pcl_ddg/features/robust_plane_fit.h"
#include "pcl_ddg/features/widening_planes.h"
#include "pcl_ddg/interruption.h"

namespace pcl_ddg {

template <typename PointInT, typename PointOutT>
void RobustNormalEstimation<PointInT, PointOutT>::computeFeature(PointCloudOut& output) {
  using Outcome = typename LocalFitEstimation<PointInT, PointOutT>::FitOutcome;
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  scales_.assign(output.size(), nan);
  confidences_.assign(output.size(), nan);
  reaches_.assign(report_reaches_ ? output.size() : 0, 0.0);
  std::vector<double> largest_reference(output.size(), -1.0);  // none: no wider plane
  // Planes widen from a k-nearest search (not a radius) along a graph whose rows are each
  // query's first kWideGraphWidth neighbours found.
  const bool widening = this->search_radius_ == 0.0 && this->searchK() >= kWideGraphWidth;
  NeighbourGraph rows;
  rows.width = kWideGraphWidth;
  if (widening) rows.neighbours.assign(output.size() * kWideGraphWidth, -1);
  this->fitEachNeighbourhood(
      output, [&](const Eigen::Matrix3Xd& neighbours, int count, const pcl::Indices& found,
                  pcl::index_t index, const Eigen::Vector3d& position, std::size_t i) {
        if (widening)
          std::copy_n(found.begin(), std::min(count, kWideGraphWidth),
                      rows.neighbours.begin() + i * kWideGraphWidth);
        if (!position.allFinite()) return Outcome::Failed;
        const RobustPlaneFit plane = fitRobustPlane(neighbours, count);
        if (!plane.valid) return Outcome::Failed;
        write(output[i], plane.normal, index, position);
        output[i].curvature = static_cast<float>(plane.surface_variation);
        scales_[i] = static_cast<float>(plane.scale);
        confidences_[i] = static_cast<float>(plane.confidence);
        largest_reference[i] = kWideResidual * plane.residual;
        return Outcome::Fitted;
      });
  if (widening) widen(output, largest_reference, std::move(rows));
  this->makeOrientationConsistent(output, [](std::size_t) {});
}

template <typename PointInT, typename PointOutT>
void RobustNormalEstimation<PointInT, PointOutT>::write(PointOutT& out, Eigen::Vector3d normal,
                                                        pcl::index_t index,
                                                        const Eigen::Vector3d& position) const {
  this->orient(normal, index, position);
  out.normal_x = static_cast<float>(normal.x());
  out.normal_y = static_cast<float>(normal.y());
  out.normal_z = static_cast<float>(normal.z());
}

template <typename PointInT, typename PointOutT>
void RobustNormalEstimation<PointInT, PointOutT>::widen(
    PointCloudOut& output, const std::vector<double>& largest_reference,
    NeighbourGraph query_graph) {
  const pcl::PointCloud<PointInT>& surface = *this->surface_;
  const pcl::PointCloud<PointInT>& input = *this->input_;
  const pcl::Indices& indices = *this->indices_;
  pcl::search::Search<PointInT>& tree = *this->tree_;
  const int threads = this->threadCount();
  // Coordinates in double as given (the exact ones when given: then the surface is the input):
  // the moments are kept about their own nodes, so nothing cancels, and the bits do not depend
  // on which points the surface holds (a tile's fit gives the whole cloud's).
  const auto absolute = [&](const PointInT& p, pcl::index_t j) -> Eigen::Vector3d {
    const auto& exact = this->getInputPositions();
    return exact ? Eigen::Vector3d(exact->col(j))
                 : Eigen::Vector3d(p.getVector3fMap().template cast<double>());
  };
  // A non-finite point is in no row; NaN puts it last in the nodes' spatial order.
  std::vector<Eigen::Vector3d> nodes(surface.size());
  for (std::size_t j = 0; j < surface.size(); ++j)
    nodes[j] = pcl::isXYZFinite(surface[j])
                   ? absolute(surface[j], static_cast<pcl::index_t>(j))
                   : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Every point of the cloud queried in its own order (the usual call): the queries are the nodes
  // and their rows the nodes' rows, taken over rather than copied (13 MB per 100k points, on a
  // fresh machine a page fault per 4 kB of them).
  bool nodes_in_order = this->surface_ == this->input_ && indices.size() == surface.size();
  for (std::size_t i = 0; nodes_in_order && i < indices.size(); ++i)
    nodes_in_order = indices[i] == static_cast<pcl::index_t>(i);
  std::vector<Eigen::Vector3d> queries;
  if (!nodes_in_order) {
    queries.resize(indices.size());
    for (std::size_t i = 0; i < indices.size(); ++i)
      queries[i] = absolute(input[indices[i]], indices[i]);
  }

  // The nodes' rows: on the input itself a query is its node and brings its row; the other
  // nodes (all of a separate search surface) search for theirs.
  const std::size_t width = kWideGraphWidth;
  NeighbourGraph node_graph;
  node_graph.width = kWideGraphWidth;
  std::vector<char> has_row(surface.size(), 0);
  std::vector<int> query_nodes(indices.size(), -1);
  if (nodes_in_order) {
    std::iota(query_nodes.begin(), query_nodes.end(), 0);
    std::fill(has_row.begin(), has_row.end(), 1);
    node_graph = std::move(query_graph);
    query_graph = NeighbourGraph();
  } else {
    node_graph.neighbours.assign(surface.size() * width, -1);
    if (this->surface_ == this->input_) {
      for (std::size_t i = 0; i < indices.size(); ++i) {
        const pcl::index_t node = indices[i];
        query_nodes[i] = node;
        if (has_row[node]) continue;
        has_row[node] = 1;
        std::copy_n(query_graph.neighbours.begin() + i * width, width,
                    node_graph.neighbours.begin() + static_cast<std::size_t>(node) * width);
      }
      query_graph = NeighbourGraph();  // every query is a node: its rows are no longer needed
    }
  }
  detail::InterruptionPoll interruption;
#pragma omp parallel num_threads(threads)
  {
    pcl::Indices found;
    std::vector<float> distances;
#pragma omp for schedule(dynamic, 256)
    for (std::ptrdiff_t j = 0; j < static_cast<std::ptrdiff_t>(surface.size()); ++j) {
      if (interruption.stopped() || has_row[j] || !pcl::isXYZFinite(surface[j])) continue;
      found.resize(width);
      distances.resize(width);
      const int answered = tree.nearestKSearch(surface, static_cast<pcl::index_t>(j),
                                               kWideGraphWidth, found, distances);
      const int count = std::min({answered, kWideGraphWidth, static_cast<int>(found.size())});
      int n = 0;
      for (int f = 0; f < count; ++f)
        if (pcl::isXYZFinite(surface[found[f]])) node_graph.neighbours[j * width + n++] = found[f];
    }
  }
  interruption.throwIfStopped();
  std::vector<Eigen::Vector3f> searched;  // where the rows were searched: their reach
  if (report_reaches_) {
    searched.resize(surface.size());
    for (std::size_t j = 0; j < surface.size(); ++j) searched[j] = surface[j].getVector3fMap();
  }
  const std::vector<WidePlane> planes =
      widestPlanes(nodes, std::move(node_graph), nodes_in_order ? nodes : queries, query_nodes,
                   query_graph, largest_reference, threads, report_reaches_ ? &searched : nullptr);
  const std::int64_t finite =
      cloud_points_ > 0 ? cloud_points_
                        : std::count_if(surface.begin(), surface.end(),
                                        [](const PointInT& p) { return pcl::isXYZFinite(p); });
  for (std::size_t i = 0; i < planes.size(); ++i) {
    if (report_reaches_) reaches_[i] = planes[i].reach;
    if (planes[i].level < 0) continue;
    write(output[i], planes[i].normal, indices[i], this->inputPosition(indices[i]));
    scales_[i] =
        static_cast<float>(std::min<std::int64_t>(kWideGraphWidth * (planes[i].level + 1), finite));
    confidences_[i] = 1.0f;
  }
}

}  // namespace pcl_ddg

#define PCL_DDG_INSTANTIATE_RobustNormalEstimation(T, NT) \
  template class pcl_ddg::RobustNormalEstimation<T, NT>;
