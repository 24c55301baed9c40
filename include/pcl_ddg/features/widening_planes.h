#pragma once
/** \file
 * Planes wider than the neighbourhood searched, from moments summed along the nearest-neighbour
 * graph (RobustNormalEstimation on noisy data).
 *
 * Each node j of a graph (its w nearest neighbours N(j), w = 32) has the moments of its
 * neighbourhood \f$ A_0(j) = \sum_{x \in N(j)} (1, x, x x^T) \f$; a level wider they are summed
 * over the neighbours, \f$ A_{l+1}(j) = \sum_{m \in N(j)} A_l(m) \f$: each point weighted by
 * the number of (l + 1)-step walks to it, a kernel that reaches l + 1 neighbourhood radii but
 * whose mass spreads as a random walk's, about \f$ \sqrt{l + 1} \f$ radii, for the cost of
 * adding w moments per point and level. Moments are kept about their own node and moved by the
 * parallel-axis rule, so far from the origin nothing cancels.
 *
 * Scale: the plane (PCA of the moments) of level l >= kFirstWideLevel is kept, and the next
 * tried, while its residual variance \f$ \lambda_0(l) \f$ stays within twice that of level
 * kFirstWideLevel - 1 (about the size searched), and only where that reference is itself noise:
 * at most largest_reference, which the caller sets from the residual of its own robust plane.
 * Residual that does not grow with the scale is noise, which a wider plane averages; residual
 * that grows is curvature or another face, where the plane stops. On clean curved data the
 * reference is curvature, far above a small plane's residual, and no level is kept.
 *
 * Reach (for fitting tile by tile): level l of node r reads the rows of the nodes within l steps
 * of r. With the nodes' search coordinates given, a bound on how far that reaches,
 * \f$ U_l(r) = \max_{m \in N(r)} \left( |m - r| + U_{l-1}(m) \right) \f$, \f$ U_{-1} = 0 \f$,
 * is carried along: every node c whose row was read, and that row's farthest point, lie within
 * \f$ U_l(r) \f$ of r along the walk, hence its row's ball \f$ |c - r| + \rho_c \le U_l(r) \f$. A
 * row short of the graph's width (fewer points than that were searched) reaches without bound.
 */
#include <Eigen/Core>
#include <vector>

#include "pcl_ddg/large_array.h"

namespace pcl_ddg {

/** Neighbour lists of a fixed width, row-major: node i's are neighbours[i * width + n], -1 for
 *  none. */
struct NeighbourGraph {
  int width = 0;
  detail::LargeArray<int> neighbours;
};

/** Levels 0 .. kWideLevels - 1 are formed; the first kFirstWideLevel only lead up to the rest,
 *  level kFirstWideLevel - 1 being the reference. */
constexpr int kWideLevels = 13;
constexpr int kFirstWideLevel = 3;
/** A kept level's residual variance is at most this many times the reference level's. */
constexpr double kWideGrowth = 2.0;

/** The widest plane of a query point. */
struct WidePlane {
  int level = -1;  ///< the level kept; -1 for none (the reference or the first wide level failed)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit, sign arbitrary; level >= 0
  /** With search_points: U (see the file's comment) of the last level the query tried (0: none
   *  tried; infinity: a query that is not a node). */
  double reach = 0.0;
};

/**
 * For each query (at queries[q]): the plane of the widest level kept (see the file's comment).
 * A query that is a node (query_nodes[q] >= 0) has that node's moments; one that is not
 * (query_nodes[q] = -1) sums its own neighbours among the nodes, query_graph's row q. nodes and
 * queries in double, in any frame (the moments are kept about their nodes, so the origin's
 * distance costs nothing; a node in no row may be NaN). Deterministic: the same input gives the
 * same bits on any number of threads, and a node's sums depend only on the nodes its walks reach.
 * largest_reference[q]: the most residual variance the reference level of query q may have for any
 * level to be kept (-1: none). search_points (optional): the nodes' coordinates in which their rows
 * were searched (the cloud's floats); given, each plane carries its reach. node_graph is taken
 * by value: moved in, its rows are renumbered in place rather than copied.
 */
std::vector<WidePlane> widestPlanes(const std::vector<Eigen::Vector3d>& nodes,
                                    NeighbourGraph node_graph,
                                    const std::vector<Eigen::Vector3d>& queries,
                                    const std::vector<int>& query_nodes,
                                    const NeighbourGraph& query_graph,
                                    const std::vector<double>& largest_reference, int threads,
                                    const std::vector<Eigen::Vector3f>* search_points = nullptr);

}  // namespace pcl_ddg
