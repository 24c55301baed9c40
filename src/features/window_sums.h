#pragma once
// The sums over every (2w+1)^2 pixel window of an organized cloud that a plane fit needs: the
// number of finite points, their coordinates and the products of their coordinates. Computed one
// tile at a time on coordinates centred in the tile (far from the origin the squares would
// otherwise cancel the covariance away) and one row at a time: each row of the tile's region is
// summed across the window's columns once, kept in a ring of 2w+1 rows, and the ring summed down
// the window. Direct sums: a window's sums are those of its points in another order, with none
// of the cancellation of differences of large prefix sums.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace pcl_ddg {
namespace detail {

class WindowSums {
 public:
  /// count, x, y, z, xx, xy, xz, yy, yz, zz (coordinates relative to centre()).
  enum Channel { kCount, kX, kY, kZ, kXX, kXY, kXZ, kYY, kYZ, kZZ, kChannels };
  static constexpr int kTileWidth = 64;

  /** finite[i]: whether point i has finite coordinates (the others count as absent); positions:
   *  the cloud's coordinates in double (null: its floats). */
  WindowSums(const pcl::PointCloud<pcl::PointXYZ>& cloud, const Eigen::Matrix3Xd* positions,
             const std::vector<std::uint8_t>& finite, int radius);

  /** Starts the tile of columns [x0, x1) and rows [y0, y1), x1 - x0 <= kTileWidth. */
  void startTile(int x0, int y0, int x1, int y1);
  /** The mean of the finite points of the tile's windows, which coordinates are relative to. */
  const Eigen::Vector3d& centre() const { return centre_; }
  /** The sums of the windows around pixels (x0 + j, y) of the tile, channel c at
   *  [c * kTileWidth + j]; rows from y0 upwards, one after another. */
  const double* rowSums(int y);

 private:
  void sumAcross(int v);  // region row v into its ring slot

  Eigen::Vector3d position(std::size_t pixel) const {
    return positions_ ? Eigen::Vector3d(positions_->col(static_cast<Eigen::Index>(pixel)))
                      : Eigen::Vector3d(cloud_[pixel].getVector3fMap().cast<double>());
  }

  const pcl::PointCloud<pcl::PointXYZ>& cloud_;
  const Eigen::Matrix3Xd* positions_;
  const std::vector<std::uint8_t>& finite_;
  int width_, height_, radius_;
  int x0_ = 0, tile_width_ = 0, next_row_ = 0;
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  std::vector<double> values_;  // one region row's channels, [c * (kTileWidth + 2 w) + k]
  std::vector<double> ring_;  // 2w+1 rows summed across, [(slot * kChannels + c) * kTileWidth + j]
  std::vector<double> sums_;  // [c * kTileWidth + j]
};

}  // namespace detail
}  // namespace pcl_ddg
