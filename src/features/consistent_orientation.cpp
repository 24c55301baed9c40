#include "pcl_ddg/features/consistent_orientation.h"

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <new>
#include <numeric>
#include <type_traits>
#include <vector>

#include "detail/disjoint_sets.h"
#include "pcl_ddg/interruption.h"
#include "pcl_ddg/search/point_kd_tree.h"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace {

using GraphEdge = std::pair<int, int>;  ///< point indices

/** Room for count edges, each constructed in place by the code that fills it, none before: the
 *  pages are first touched where the edges are written. GraphEdge needs no destruction. */
class EdgeSlots {
 public:
  explicit EdgeSlots(std::size_t count)
      : count_(count), data_(std::allocator<GraphEdge>().allocate(count)) {}
  ~EdgeSlots() { std::allocator<GraphEdge>().deallocate(data_, count_); }
  EdgeSlots(const EdgeSlots&) = delete;
  EdgeSlots& operator=(const EdgeSlots&) = delete;
  GraphEdge* data() const { return data_; }

 private:
  static_assert(std::is_trivially_destructible_v<GraphEdge>);
  std::size_t count_;
  GraphEdge* data_;
};

/** The edges a spanning forest is grown over, wherever they are stored. */
struct EdgeSpan {
  const GraphEdge* data;
  std::size_t count;
  std::size_t size() const { return count; }
  const GraphEdge& operator[](std::size_t e) const { return data[e]; }
};

/** Points with a finite coordinate and normal. */
std::vector<char> orientablePoints(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                   const pcl::PointCloud<pcl::Normal>& normals) {
  if (normals.size() != cloud.size()) {
    throw pcl::BadArgumentException("orientNormalsConsistently: " + std::to_string(normals.size()) +
                                    " normals for " + std::to_string(cloud.size()) + " points");
  }
  std::vector<char> usable(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    usable[i] = pcl::isXYZFinite(cloud[i]) && pcl::isNormalFinite(normals[i]);
  }
  return usable;
}

/**
 * The tree (CSR: degree offsets, adjacent points) with a reference: confident points keep the
 * reference's sign, each region of ambiguous points is made consistent along the tree and takes
 * the sign that agrees with the reference most (see the header).
 */
ConsistentOrientationReport orientByReference(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                              pcl::PointCloud<pcl::Normal>& normals,
                                              const std::vector<char>& usable,
                                              const std::vector<int>& degree,
                                              const std::vector<int>& adjacent,
                                              detail::DisjointSets& sets,
                                              const ConsistentOrientationOptions& options) {
  const int n = static_cast<int>(cloud.size());
  ConsistentOrientationReport report;
  // n . d for every usable point, in double: UTM coordinates in float lose the direction to a
  // nearby viewpoint otherwise.
  std::vector<double> facing(static_cast<std::size_t>(n), 0.0);
  std::vector<char> confident(static_cast<std::size_t>(n), 0),
      turned(static_cast<std::size_t>(n), 0);
  const auto unitNormal = [&](int i) {
    return Eigen::Vector3d(normals[i].getNormalVector3fMap().cast<double>().normalized());
  };
  const auto flip = [&](int i) {
    normals[i].normal_x = -normals[i].normal_x;
    normals[i].normal_y = -normals[i].normal_y;
    normals[i].normal_z = -normals[i].normal_z;
    facing[i] = -facing[i];
    turned[i] = !turned[i];
  };
  for (int i = 0; i < n; ++i) {
    if (!usable[i]) continue;
    ++report.oriented_points;
    if (sets.find(i) == i) ++report.components;
    const Eigen::Vector3d d =
        options.viewpoint
            ? Eigen::Vector3d(
                  (*options.viewpoint - cloud[i].getVector3fMap().cast<double>()).normalized())
            : Eigen::Vector3d(options.up->normalized());
    facing[i] = unitNormal(i).dot(d);
    if (std::abs(facing[i]) >= options.confidence) {
      confident[i] = 1;
      ++report.confident_points;
      if (facing[i] < 0.0) flip(i);
    }
  }
  // Ambiguous regions, each grown from its most confident point (the most reliable start).
  std::vector<int> by_facing;
  for (int i = 0; i < n; ++i)
    if (usable[i] && !confident[i]) by_facing.push_back(i);
  std::stable_sort(by_facing.begin(), by_facing.end(),
                   [&](int a, int b) { return std::abs(facing[a]) > std::abs(facing[b]); });
  std::vector<char> reached(static_cast<std::size_t>(n), 0);
  std::vector<int> region;
  for (const int seed : by_facing) {
    if (reached[seed]) continue;
    ++report.ambiguous_regions;
    reached[seed] = 1;
    region.assign(1, seed);
    double votes = 0.0;  // of the tree edges to confident points: +1 agree, -1 disagree
    for (std::size_t next = 0; next < region.size(); ++next) {
      const int from = region[next];
      const Eigen::Vector3f parent = normals[from].getNormalVector3fMap();
      for (int k = degree[from]; k < degree[from + 1]; ++k) {
        const int to = adjacent[k];
        if (confident[to]) {
          votes += normals[to].getNormalVector3fMap().dot(parent) < 0.0f ? -1.0 : 1.0;
          continue;
        }
        if (reached[to]) continue;
        reached[to] = 1;
        if (normals[to].getNormalVector3fMap().dot(parent) < 0.0f) flip(to);
        region.push_back(to);
      }
    }
    // The region's sign: the one that agrees with the reference most, sum n . d >= 0 (each
    // point's sign is a coin toss there, their sum is not). The tree's edges to confident points
    // decide only a tie (a cylinder's side with horizontal normals under "up"): on aerial surveys
    // they are the worse judge (autzen 99.37 % up instead of 99.43), the step across a roof's
    // edge or a wall's foot being a coin toss of its own.
    double agreement = 0.0;
    for (const int i : region) agreement += facing[i];
    if (agreement < 0.0 || (agreement == 0.0 && votes < 0.0)) {
      for (const int i : region) flip(i);
    }
  }
  for (int i = 0; i < n; ++i) {
    report.flipped_points += turned[i];
    if (!confident[i]) report.propagated_flips += turned[i];
  }
  return report;
}

/**
 * The minimum spanning forest of the graph (Kruskal; weights 1 - |n_a . n_b| bucketed to 16
 * bits by a stable counting sort, so that the order, and the result, do not depend on threads),
 * then each tree walked from its highest point.
 */
ConsistentOrientationReport orientAlongSpanningForest(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                                      pcl::PointCloud<pcl::Normal>& normals,
                                                      const std::vector<char>& usable,
                                                      EdgeSpan edges,
                                                      const ConsistentOrientationOptions& options) {
  const int n = static_cast<int>(cloud.size());
  constexpr int kBuckets = 1 << 16;
  std::vector<std::uint16_t> key(edges.size());
  std::vector<std::int64_t> start(kBuckets + 1, 0);
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const Eigen::Vector3f na = normals[edges[e].first].getNormalVector3fMap().normalized();
    const Eigen::Vector3f nb = normals[edges[e].second].getNormalVector3fMap().normalized();
    const Eigen::Vector3f along =
        (cloud[edges[e].second].getVector3fMap() - cloud[edges[e].first].getVector3fMap())
            .normalized();
    // Hoppe's 1 - |na . nb|, which also finds antiparallel normals cheap: across the two sheets
    // of a thin part (an ear, a leg) the step runs along the normals, so it is charged for that.
    float weight = 1.0f - std::abs(na.dot(nb));
    if (along.allFinite()) weight += 0.5f * (std::abs(na.dot(along)) + std::abs(nb.dot(along)));
    key[e] =
        static_cast<std::uint16_t>(std::clamp(0.5f * weight, 0.0f, 1.0f) * (kBuckets - 1) + 0.5f);
    ++start[key[e] + 1];
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::int64_t> order(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e)
    order[start[key[e]]++] = static_cast<std::int64_t>(e);

  detail::DisjointSets sets(n);
  std::vector<int> degree(n + 1, 0);
  std::vector<GraphEdge> tree;
  tree.reserve(static_cast<std::size_t>(n));
  for (const std::int64_t e : order) {
    if (!sets.unite(edges[e].first, edges[e].second)) continue;
    tree.push_back(edges[e]);
    ++degree[edges[e].first + 1];
    ++degree[edges[e].second + 1];
  }
  std::partial_sum(degree.begin(), degree.end(), degree.begin());
  std::vector<int> adjacent(2 * tree.size()), fill(degree.begin(), degree.end() - 1);
  for (const auto& [a, b] : tree) {
    adjacent[fill[a]++] = b;
    adjacent[fill[b]++] = a;
  }

  if (options.viewpoint || options.up) {
    return orientByReference(cloud, normals, usable, degree, adjacent, sets, options);
  }

  // Seeds: the first point of a tree met in this order. Up: from the highest point down. Facing
  // a viewpoint: from the point that sees it most squarely, so that no seed is a point seen
  // edge-on (a sphere's limb), whose sign would be a coin toss.
  std::vector<float> seed_rank(static_cast<std::size_t>(n), 0.0f);
  std::vector<int> by_rank;
  by_rank.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    if (!usable[i]) continue;
    by_rank.push_back(i);
    seed_rank[i] =
        options.viewpoint
            ? std::abs(normals[i].getNormalVector3fMap().normalized().dot(
                  (options.viewpoint->cast<float>() - cloud[i].getVector3fMap()).normalized()))
            : cloud[i].z;
  }
  std::stable_sort(by_rank.begin(), by_rank.end(),
                   [&](int a, int b) { return seed_rank[a] > seed_rank[b]; });

  ConsistentOrientationReport report;
  report.oriented_points = static_cast<std::int64_t>(by_rank.size());
  std::vector<char> reached(static_cast<std::size_t>(n), 0);
  std::vector<int> queue;
  const auto flip = [&](int i) {
    normals[i].normal_x = -normals[i].normal_x;
    normals[i].normal_y = -normals[i].normal_y;
    normals[i].normal_z = -normals[i].normal_z;
    ++report.flipped_points;
  };
  for (const int seed : by_rank) {
    if (reached[seed]) continue;
    ++report.components;
    const Eigen::Vector3f n0 = normals[seed].getNormalVector3fMap();
    const float facing =
        options.viewpoint ? n0.dot(options.viewpoint->cast<float>() - cloud[seed].getVector3fMap())
                          : n0.z();
    if (facing < 0.0f) flip(seed);
    reached[seed] = 1;
    queue.assign(1, seed);
    for (std::size_t next = 0; next < queue.size(); ++next) {
      const int from = queue[next];
      const Eigen::Vector3f parent = normals[from].getNormalVector3fMap();
      for (int k = degree[from]; k < degree[from + 1]; ++k) {
        const int to = adjacent[k];
        if (reached[to]) continue;
        reached[to] = 1;
        if (normals[to].getNormalVector3fMap().dot(parent) < 0.0f) flip(to);
        queue.push_back(to);
      }
    }
  }
  return report;
}

}  // namespace

ConsistentOrientationReport orientNormalsConsistently(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                                      pcl::PointCloud<pcl::Normal>& normals,
                                                      const ConsistentOrientationOptions& options) {
  if (options.k < 1) throw pcl::BadArgumentException("orientNormalsConsistently: k must be >= 1");
  const std::vector<char> usable = orientablePoints(cloud, normals);
  std::vector<float> xyz;
  std::vector<pcl::index_t> ids;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!usable[i]) continue;
    xyz.insert(xyz.end(), {cloud[i].x, cloud[i].y, cloud[i].z});
    ids.push_back(static_cast<pcl::index_t>(i));
  }
  const std::vector<pcl::index_t> points = ids;
  const detail::PointKdTree tree(std::move(xyz), std::move(ids));
  // Each point's k nearest others fill its own k slots: the edge list does not depend on threads.
  // The slots are constructed there, by the point, not filled before the search: on a fresh VM
  // the first touch of n k slots' pages alone took longer than Ctrl-C may wait.
  const int k = options.k;
  const std::size_t slot_count = points.size() * static_cast<std::size_t>(k);
  const EdgeSlots slots(slot_count);
  detail::InterruptionPoll interruption;
#ifdef _OPENMP
  const int threads =
      options.threads > 0 ? static_cast<int>(options.threads) : omp_get_max_threads();
#endif
#pragma omp parallel num_threads(threads)
  {
    pcl::Indices found;
    std::vector<float> distances;
#pragma omp for schedule(dynamic, 1024)
    for (std::int64_t p = 0; p < static_cast<std::int64_t>(points.size()); ++p) {
      if (interruption.stopped()) continue;
      const int i = points[p];
      tree.nearestK(cloud[i].data, k + 1, found, distances);
      GraphEdge* own = slots.data() + p * k;
      int slot = 0;
      for (const pcl::index_t j : found) {
        if (j == i || slot == k) continue;
        new (own + slot++) GraphEdge(std::min<int>(i, j), std::max<int>(i, j));
      }
      while (slot < k) new (own + slot++) GraphEdge(-1, -1);  // fewer neighbours than k
    }
  }
  interruption.throwIfStopped();
  // Every slot holds an edge now (GraphEdge is trivially destructible: none is destroyed).
  GraphEdge* const end = std::remove_if(slots.data(), slots.data() + slot_count,
                                        [](const GraphEdge& e) { return e.first < 0; });
  return orientAlongSpanningForest(cloud, normals, usable,
                                   {slots.data(), static_cast<std::size_t>(end - slots.data())},
                                   options);
}

ConsistentOrientationReport orientNormalsConsistently(const MeshTopology& topology,
                                                      const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                                      pcl::PointCloud<pcl::Normal>& normals,
                                                      const ConsistentOrientationOptions& options) {
  if (cloud.size() != static_cast<std::size_t>(topology.numVertices())) {
    throw pcl::BadArgumentException("orientNormalsConsistently: the cloud has " +
                                    std::to_string(cloud.size()) + " points for a mesh of " +
                                    std::to_string(topology.numVertices()) + " vertices");
  }
  const std::vector<char> usable = orientablePoints(cloud, normals);
  std::vector<GraphEdge> edges;
  edges.reserve(static_cast<std::size_t>(topology.numEdges()));
  for (int e = 0; e < topology.numEdges(); ++e) {
    const int a = topology.edgeVertices()(0, e), b = topology.edgeVertices()(1, e);
    if (usable[a] && usable[b]) edges.emplace_back(a, b);
  }
  return orientAlongSpanningForest(cloud, normals, usable, {edges.data(), edges.size()}, options);
}

ConsistentOrientationReport orientNormalsConsistently(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                                      pcl::PointCloud<pcl::Normal>& normals,
                                                      const std::vector<GraphEdge>& edges,
                                                      const ConsistentOrientationOptions& options) {
  const std::vector<char> usable = orientablePoints(cloud, normals);
  const auto outside = [&](int i) { return i < 0 || i >= static_cast<int>(cloud.size()); };
  std::vector<GraphEdge> usable_edges;
  usable_edges.reserve(edges.size());
  for (const auto& [a, b] : edges) {
    if (outside(a) || outside(b)) {
      throw pcl::BadArgumentException("orientNormalsConsistently: the edge " + std::to_string(a) +
                                      "-" + std::to_string(b) + " leaves the cloud of " +
                                      std::to_string(cloud.size()) + " points");
    }
    if (usable[a] && usable[b]) usable_edges.emplace_back(a, b);
  }
  return orientAlongSpanningForest(cloud, normals, usable,
                                   {usable_edges.data(), usable_edges.size()}, options);
}

ConsistentOrientationReport orientNormalsConsistently(
    const OrganizedGridSearch<pcl::PointXYZ>& grid, pcl::PointCloud<pcl::Normal>& normals,
    const ConsistentOrientationOptions& options) {
  const auto cloud = grid.getInputCloud();
  if (!cloud) throw pcl::BadArgumentException("orientNormalsConsistently: the grid has no cloud");
  const std::vector<char> usable = orientablePoints(*cloud, normals);
  const int width = static_cast<int>(cloud->width);
  std::vector<GraphEdge> edges;
  // Each step once: to the right, and to the three pixels of the row below.
  const int steps[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
  for (int i = 0; i < static_cast<int>(cloud->size()); ++i) {
    if (!usable[i]) continue;
    for (const auto& step : steps) {
      if (!(grid.allowedSteps(i) & (1u << grid.stepBit(step[0], step[1])))) continue;
      const int j = i + step[1] * width + step[0];
      if (usable[j]) edges.emplace_back(i, j);
    }
  }
  return orientAlongSpanningForest(*cloud, normals, usable, {edges.data(), edges.size()}, options);
}

}  // namespace pcl_ddg
