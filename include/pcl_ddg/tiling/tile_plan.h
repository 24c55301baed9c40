#pragma once
/** \file
 * Spatial tiles of a point cloud, so that it can be processed piece by piece: out of core, or by
 * independent workers. A plan is cut from a histogram of the points on a regular grid over their
 * bounding box (one streaming pass over a file fills it): boxes of grid cells are halved along
 * their longest side, at the cell boundary nearest the median, until each holds at most the
 * requested number of points. Every finite point belongs to exactly one tile (its cell's); a tile
 * is processed with a halo, the points around it within a margin, for the neighbourhoods of its
 * points near the border.
 */
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace pcl_ddg {

/** Point counts per cell of a resolution^3 grid over a bounding box. */
class PointHistogram {
 public:
  PointHistogram(const Eigen::AlignedBox3d& bounds, int resolution);

  /** Counts a finite point (points outside the bounds count in the nearest cell). */
  void add(const Eigen::Vector3d& point) { ++counts_[cellOf(point)]; }
  /** The linear index of the cell holding point. */
  int cellOf(const Eigen::Vector3d& point) const;

  const Eigen::AlignedBox3d& bounds() const { return bounds_; }
  int resolution() const { return resolution_; }
  const std::vector<std::int64_t>& counts() const { return counts_; }

 private:
  Eigen::AlignedBox3d bounds_;
  int resolution_;
  Eigen::Vector3d cells_per_length_;
  std::vector<std::int64_t> counts_;
};

struct Tile {
  Eigen::Vector3i first_cell;  ///< the tile is the cells [first_cell, end_cell) on each axis
  Eigen::Vector3i end_cell;
  Eigen::AlignedBox3d box;  ///< the cells' extent
  std::int64_t points = 0;  ///< points of its own (its halo not counted)
};

struct TilePlan {
  PointHistogram histogram;
  std::vector<Tile> tiles;
  std::vector<int> tile_of_cell;  ///< by the histogram's linear cell index

  int tileOf(const Eigen::Vector3d& point) const { return tile_of_cell[histogram.cellOf(point)]; }
  /** The plan as JSON (bounds, resolution, every tile's cells, box and count): what an
   *  independent worker needs to know which points are its own. */
  std::string toJson() const;
};

/** Cuts the histogram into tiles of at most max_points_per_tile points each, where a single cell
 *  allows it (a cell is never split: a denser cell is a tile of its own, over the limit). */
TilePlan planTiles(const PointHistogram& histogram, std::int64_t max_points_per_tile);

}  // namespace pcl_ddg
