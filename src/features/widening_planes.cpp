#include "pcl_ddg/features/widening_planes.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>

#include "pcl_ddg/features/plane_fit.h"
#include "pcl_ddg/features/spatial_order.h"
#include "pcl_ddg/large_array.h"
#include "point_moments.h"

namespace pcl_ddg {

namespace {

using detail::PointMoments;

constexpr int kQueryBlock = 64;  ///< queries whose planes are solved together

/** The moments about `at` of the nodes of a graph row, each as a point (previous == nullptr) or
 *  as its moments of the previous level. */
PointMoments sumOverRow(const Eigen::Vector3d& at, const int* row, int width,
                        const std::vector<Eigen::Vector3d>& nodes,
                        const detail::LargeArray<PointMoments>* previous) {
  static const PointMoments kPoint{1.0};
  PointMoments sum;
  for (int n = 0; n < width; ++n) {
    const int j = row[n];
    if (j >= 0) sum.addMoved(previous ? (*previous)[j] : kPoint, nodes[j] - at);
  }
  return sum;
}

/** rows[r] = (the rows as given)[order[r]] for each row of width entries, order a permutation:
 *  in place (the graph is the largest array here), following each cycle of the permutation once
 *  with one row held aside. */
template <typename Rows>
void gatherRows(Rows& rows, int width, const std::vector<int>& order) {
  std::vector<char> placed(order.size(), 0);
  std::vector<typename Rows::value_type> held(static_cast<std::size_t>(width));
  const auto row = [&](std::size_t r) { return rows.begin() + r * width; };
  for (std::size_t start = 0; start < order.size(); ++start) {
    if (placed[start]) continue;
    std::copy_n(row(start), width, held.begin());
    for (std::size_t r = start;;) {
      placed[r] = 1;
      const auto from = static_cast<std::size_t>(order[r]);
      if (from == start) {
        std::copy_n(held.begin(), width, row(r));
        break;
      }
      std::copy_n(row(from), width, row(r));
      r = from;
    }
  }
}

/** U_l of a row (widening_planes.h): the farthest its members' own reach extends along the row,
 *  previous holding U_{l-1} (nullptr: level 0). */
double rowReach(const Eigen::Vector3f& at, const int* row, int width,
                const std::vector<Eigen::Vector3f>& points, const std::vector<double>* previous) {
  double reach = 0.0;
  for (int n = 0; n < width; ++n) {
    const int j = row[n];
    if (j < 0) return std::numeric_limits<double>::infinity();
    const double step = (points[j].cast<double>() - at.cast<double>()).norm();
    reach = std::max(reach, step + (previous ? (*previous)[j] : 0.0));
  }
  return reach;
}

}  // namespace

std::vector<WidePlane> widestPlanes(const std::vector<Eigen::Vector3d>& nodes,
                                    NeighbourGraph node_graph,
                                    const std::vector<Eigen::Vector3d>& queries,
                                    const std::vector<int>& query_nodes,
                                    const NeighbourGraph& query_graph,
                                    const std::vector<double>& largest_reference, int threads,
                                    const std::vector<Eigen::Vector3f>* search_points) {
  // Nodes renumbered in space-filling order: a row's moments then lie near each other in memory.
  std::vector<Eigen::Vector3f> approximate(nodes.size());
  for (std::size_t j = 0; j < nodes.size(); ++j) approximate[j] = nodes[j].cast<float>();
  const std::vector<int> order = detail::spatialOrder(approximate);
  std::vector<int> rank(nodes.size());
  for (std::size_t r = 0; r < order.size(); ++r) rank[order[r]] = static_cast<int>(r);
  const int width = node_graph.width;
  std::vector<Eigen::Vector3d> at(nodes.size());
  std::vector<Eigen::Vector3f> searched_at(search_points ? nodes.size() : 0);
  for (std::size_t r = 0; r < order.size(); ++r) {
    at[r] = nodes[order[r]];
    if (search_points) searched_at[r] = (*search_points)[order[r]];
  }
  detail::LargeArray<int>& rows = node_graph.neighbours;  // renumbered and reordered where they are
  for (int& j : rows)
    if (j >= 0) j = rank[j];
  gatherRows(rows, width, order);
  // Rows of the queries that are not nodes (none where every query is one).
  const bool all_nodes =
      std::all_of(query_nodes.begin(), query_nodes.end(), [](int node) { return node >= 0; });
  detail::LargeArray<int> query_rows(all_nodes ? 0 : query_graph.neighbours.size());
  for (std::size_t i = 0; i < query_rows.size(); ++i)
    query_rows[i] = query_graph.neighbours[i] < 0 ? -1 : rank[query_graph.neighbours[i]];

  // Queries visited in their nodes' order (the others after them, as given), and their state
  // kept in that order: each level then reads the moments in sequence.
  std::vector<int> visit(queries.size());
  std::iota(visit.begin(), visit.end(), 0);
  const auto key = [&](int q) {
    return query_nodes[q] >= 0 ? rank[query_nodes[q]] : static_cast<int>(nodes.size());
  };
  std::stable_sort(visit.begin(), visit.end(), [&](int a, int b) { return key(a) < key(b); });
  std::vector<WidePlane> kept(queries.size());
  std::vector<double> reference(queries.size());  // lambda0 of level kFirstWideLevel - 1
  std::vector<char> stopped(queries.size(), 0);   // a level's residual was too large
  using Moments = detail::LargeArray<PointMoments>;
  Moments level_moments, previous;                  // A_l and A_{l-1} of the nodes
  std::vector<double> level_reach, previous_reach;  // U_l and U_{l-1} (search_points given)
  for (int level = 0; level < kWideLevels; ++level) {
    std::swap(previous, level_moments);
    std::swap(previous_reach, level_reach);
    level_moments.resize(at.size());
    level_reach.resize(searched_at.size());
    const Moments* below = level == 0 ? nullptr : &previous;
    const std::vector<double>* reach_below = level == 0 ? nullptr : &previous_reach;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::ptrdiff_t r = 0; r < static_cast<std::ptrdiff_t>(at.size()); ++r) {
      level_moments[r] = sumOverRow(at[r], &rows[r * width], width, at, below);
      if (search_points)
        level_reach[r] =
            rowReach(searched_at[r], &rows[r * width], width, searched_at, reach_below);
    }
    if (level + 1 < kFirstWideLevel) continue;
    // The queries' planes a block at a time, solved together in the CPU's vector lanes.
    std::ptrdiff_t widening = 0;
    const std::ptrdiff_t blocks =
        (static_cast<std::ptrdiff_t>(queries.size()) + kQueryBlock - 1) / kQueryBlock;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : widening)
    for (std::ptrdiff_t block = 0; block < blocks; ++block) {
      const std::ptrdiff_t first = block * kQueryBlock;
      const int size =
          static_cast<int>(std::min<std::ptrdiff_t>(kQueryBlock, queries.size() - first));
      double xx[kQueryBlock], xy[kQueryBlock], xz[kQueryBlock], yy[kQueryBlock], yz[kQueryBlock],
          zz[kQueryBlock], trace[kQueryBlock];
      double nx[kQueryBlock], ny[kQueryBlock], nz[kQueryBlock], variation[kQueryBlock];
      std::uint8_t valid[kQueryBlock];
      int member[kQueryBlock];  // the visit of each covariance
      int count = 0;
      for (std::ptrdiff_t v = first; v < first + size; ++v) {
        if (stopped[v]) continue;
        const int q = visit[v];
        const int node = query_nodes[q];
        if (!(largest_reference[q] >= 0.0)) {  // no plane to widen from: nothing read
          stopped[v] = 1;
          continue;
        }
        if (search_points)
          kept[v].reach =
              node >= 0 ? level_reach[rank[node]] : std::numeric_limits<double>::infinity();
        const PointMoments m =
            node >= 0 ? level_moments[rank[node]]
                      : sumOverRow(queries[q],
                                   &query_rows[static_cast<std::size_t>(q) * query_graph.width],
                                   query_graph.width, at, below);
        if (!(m.weight >= 3.0)) {
          stopped[v] = 1;
          continue;
        }
        const Eigen::Matrix3d covariance = m.covariance();
        xx[count] = covariance(0, 0), xy[count] = covariance(0, 1), xz[count] = covariance(0, 2);
        yy[count] = covariance(1, 1), yz[count] = covariance(1, 2), zz[count] = covariance(2, 2);
        trace[count] = covariance.trace();
        member[count++] = static_cast<int>(v);
      }
      fitPlaneNormals(count, {xx, xy, xz, yy, yz, zz}, {nx, ny, nz, variation, valid});
      for (int i = 0; i < count; ++i) {
        const std::ptrdiff_t v = member[i];
        const int q = visit[v];
        const double lambda0 = variation[i] * trace[i];
        const bool wide = level >= kFirstWideLevel;
        if (!valid[i] || !(lambda0 <= (wide ? kWideGrowth * reference[v] : largest_reference[q]))) {
          stopped[v] = 1;
          continue;
        }
        if (wide) {
          kept[v].level = level;
          kept[v].normal = Eigen::Vector3d(nx[i], ny[i], nz[i]);
        } else {
          reference[v] = lambda0;
        }
        ++widening;
      }
    }
    if (widening == 0) break;  // clean data: no plane widens, no need for the next level
  }
  // Back to the queries' order: kept[q] = kept[v] of the v that visited q.
  std::vector<int> visited_at(visit.size());
  for (std::size_t v = 0; v < visit.size(); ++v) visited_at[visit[v]] = static_cast<int>(v);
  gatherRows(kept, 1, visited_at);
  return kept;
}

}  // namespace pcl_ddg
