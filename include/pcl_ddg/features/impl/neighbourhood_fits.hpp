#pragma once
#include <pcl/common/point_tests.h>

#include <algorithm>
#include <vector>

#include "pcl_ddg/features/neighbourhood_fits.h"
#include "pcl_ddg/features/spatial_order.h"
#include "pcl_ddg/interruption.h"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace detail {

template <typename PointInT>
FitCounts fitNeighbourhoods(const NeighbourhoodQueries<PointInT>& queries,
                            const NeighbourhoodFit& fit) {
  const pcl::PointCloud<PointInT>& input = *queries.input;
  const pcl::PointCloud<PointInT>& surface = *queries.surface;
  const pcl::Indices& indices = *queries.indices;
  pcl::search::Search<PointInT>& tree = *queries.tree;
  std::int64_t failed = 0, fell_back = 0;
  // Queried in space-filling order (each result still goes to its point's place): consecutive
  // queries share tree nodes and neighbours, whatever order the cloud is stored in.
  std::vector<Eigen::Vector3f> query_positions(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i)
    query_positions[i] = input[indices[i]].getVector3fMap();
  const std::vector<int> order = spatialOrder(query_positions);
  const bool capped_radius = queries.radius > 0.0 && queries.max_neighbours > 0;
  InterruptionPoll interruption;
#pragma omp parallel num_threads(queries.threads) reduction(+ : failed, fell_back)
  {
    // Per-thread buffers, grown once and reused for every point.
    pcl::Indices neighbours, finite_neighbours;
    std::vector<float> squared_distances;
    Eigen::Matrix3Xd local(3, 64);
#pragma omp for schedule(dynamic, 256)
    for (std::ptrdiff_t visit = 0; visit < static_cast<std::ptrdiff_t>(indices.size()); ++visit) {
      if (interruption.stopped()) continue;
      const std::ptrdiff_t i = order[visit];
      const PointInT& query = input[indices[i]];
      // Sized to k before every search, as pcl::NormalEstimationOMP does: a search may write its
      // answer into them without resizing (PCL's own tests rely on it).
      const auto presize = [&](int size) {
        neighbours.resize(std::max(size, 0));
        squared_distances.resize(std::max(size, 0));
      };
      presize(queries.k);
      const bool finite = pcl::isXYZFinite(query);
      int found = !finite         ? 0
                  : capped_radius ? tree.radiusSearch(input, indices[i], queries.radius, neighbours,
                                                      squared_distances, queries.max_neighbours)
                                  : (*queries.search)(input, indices[i], queries.search_parameter,
                                                      neighbours, squared_distances);
      if (queries.radius > 0.0 && finite && found < static_cast<int>(queries.min_neighbours)) {
        presize(static_cast<int>(queries.min_neighbours));
        found = tree.nearestKSearch(input, indices[i], static_cast<int>(queries.min_neighbours),
                                    neighbours, squared_distances);
      }
      found = std::min(found, static_cast<int>(neighbours.size()));
      // In double, relative to the query point: exact differences of the exact coordinates.
      const auto position = [&](pcl::index_t j) -> Eigen::Vector3d {
        if (queries.positions) return queries.positions->col(j);
        return surface[j].getVector3fMap().template cast<double>();
      };
      const Eigen::Vector3d origin =
          queries.positions ? Eigen::Vector3d(queries.positions->col(indices[i]))
                            : Eigen::Vector3d(query.getVector3fMap().template cast<double>());
      if (local.cols() < found) local.resize(3, found);
      finite_neighbours.resize(std::max(found, 0));
      int count = 0;
      // The neighbours' columns are scattered over the positions: ask for all of them at once.
      if (queries.positions)
        for (int n = 0; n < found; ++n)
          __builtin_prefetch(queries.positions->col(neighbours[n]).data());
      for (int n = 0; n < found; ++n) {
        const pcl::index_t j = neighbours[n];
        // With exact positions their NaN marks a point left out: one read per neighbour.
        const Eigen::Vector3d p = position(j);
        if (queries.positions ? p.allFinite() : pcl::isXYZFinite(surface[j])) {
          finite_neighbours[count] = j;
          local.col(count++) = p - origin;
        }
      }
      const FitOutcome outcome =
          fit(local, count, finite_neighbours, indices[i], origin, static_cast<std::size_t>(i));
      if (outcome == FitOutcome::Failed) ++failed;
      if (outcome == FitOutcome::FellBack) ++fell_back;
    }
  }
  interruption.throwIfStopped();
  return {failed, fell_back};
}

}  // namespace detail
}  // namespace pcl_ddg
