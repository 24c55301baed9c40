#pragma once
/** \file
 * Per-thread "visited" marks for graph searches: one stamp per vertex, and a query marks a vertex
 * by writing the query's stamp, so starting a query costs nothing (no clearing, no allocation once
 * the array has grown to the mesh size).
 */
#include <cstdint>
#include <vector>

namespace pcl_ddg {
namespace detail {

class VisitStamps {
 public:
  /** This thread's instance, grown to at least num_vertices entries. */
  static VisitStamps& forThisThread(int num_vertices);

  /** Starts a new query: every vertex is unvisited. */
  void startQuery();

  /** Marks v; true if it was not yet visited in this query. */
  bool visit(int v) {
    if (stamps_[v] == current_) return false;
    stamps_[v] = current_;
    return true;
  }

 private:
  std::vector<std::uint32_t> stamps_;
  std::uint32_t current_ = 0;
};

}  // namespace detail
}  // namespace pcl_ddg
