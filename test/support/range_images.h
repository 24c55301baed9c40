#pragma once
// Synthetic range images: analytic surfaces seen by a pinhole camera at the origin (z forward,
// y down), as an organized cloud with NaN where a ray misses, and the exact normal per pixel.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <vector>

namespace pcl_ddg {
namespace test {

enum class RangeScene {
  Plane,     ///< a tilted plane filling the view
  Sphere,    ///< radius 1 at depth 2.5 (rays that miss: NaN)
  Cylinder,  ///< radius 0.8, axis along y at depth 2.5
  BoxOnWall  ///< a box face at depth 2.85 before a tilted wall at depth 3: a 5 % depth step
};

struct PinholeCamera {
  int width = 160;
  int height = 120;
  double focal = 131.25;  ///< pixels (a Kinect's 525 at 640 x 480, scaled)
  /** The same field of view at another resolution. */
  PinholeCamera scaled(double factor) const;
};

struct RangeImage {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;  ///< organized; sensor origin = the offset
  std::vector<Eigen::Vector3d> normals;       ///< exact, towards the camera; NaN on a miss
  /** For BoxOnWall: whether the pixel is within `pixels` of a pixel of the other surface. */
  std::vector<int> pixels_from_step;
};

/** relative_noise: each range multiplied by 1 + relative_noise * N(0, 1). The camera and the
 *  scene are moved by offset (the cloud's sensor origin is set to it). */
RangeImage renderRangeImage(RangeScene scene, const PinholeCamera& camera,
                            double relative_noise = 0.0, unsigned seed = 1,
                            const Eigen::Vector3d& offset = Eigen::Vector3d::Zero());

/** Which pixels of an organized cloud's (2r + 1)^2 window a walk from its centre reaches, by the
 *  rule of organized_grid_search.h written out here (a flood fill over the window, no code shared
 *  with the search): a step joins two 8-adjacent pixels of the window when both hold finite
 *  points and their ranges (distances from the cloud's sensor origin, here in double) differ by
 *  at most max_depth_jump times the smaller one. */
class WindowReachOracle {
 public:
  WindowReachOracle(const pcl::PointCloud<pcl::PointXYZ>& cloud, double max_depth_jump);
  /** The reached pixel indices, sorted (empty where the centre has no finite point). ambiguous
   *  (if given) is set when a step tested lies within 1e-6 of the rule's threshold, where the
   *  search's float ranges could fall on the other side. */
  std::vector<int> reach(int index, int radius, bool* ambiguous = nullptr) const;

 private:
  int width_, height_;
  double max_depth_jump_;
  std::vector<double> range_;  ///< NaN without a finite point
};

}  // namespace test
}  // namespace pcl_ddg
