#pragma once
// Weighted sums of points about a reference point: the weight, the first moments and the six
// distinct second moments, which is all a plane fit needs. Summed point by point (unit weights:
// the robust fit's nested neighbourhoods) or moved from another reference by the parallel-axis
// rule (the wider planes' level sums); relative coordinates keep the covariance's subtraction from
// cancelling far from the origin.
#include <Eigen/Core>

namespace pcl_ddg {
namespace detail {

struct PointMoments {
  double weight = 0.0, x = 0.0, y = 0.0, z = 0.0, xx = 0.0, xy = 0.0, xz = 0.0, yy = 0.0, yz = 0.0,
         zz = 0.0;

  /** Adds a point of unit weight. */
  void add(const Eigen::Vector3d& p) {
    weight += 1.0;
    x += p.x();
    y += p.y();
    z += p.z();
    xx += p.x() * p.x();
    xy += p.x() * p.y();
    xz += p.x() * p.z();
    yy += p.y() * p.y();
    yz += p.y() * p.z();
    zz += p.z() * p.z();
  }
  /** Adds other, taken about a reference d from this one's: x - ours = (x - theirs) + d. */
  void addMoved(const PointMoments& o, const Eigen::Vector3d& d) {
    weight += o.weight;
    x += o.x + o.weight * d.x();
    y += o.y + o.weight * d.y();
    z += o.z + o.weight * d.z();
    xx += o.xx + 2.0 * o.x * d.x() + o.weight * d.x() * d.x();
    yy += o.yy + 2.0 * o.y * d.y() + o.weight * d.y() * d.y();
    zz += o.zz + 2.0 * o.z * d.z() + o.weight * d.z() * d.z();
    xy += o.xy + o.x * d.y() + o.y * d.x() + o.weight * d.x() * d.y();
    xz += o.xz + o.x * d.z() + o.z * d.x() + o.weight * d.x() * d.z();
    yz += o.yz + o.y * d.z() + o.z * d.y() + o.weight * d.y() * d.z();
  }
  /** The number of points added with unit weights. */
  int count() const { return static_cast<int>(weight); }
  Eigen::Vector3d centroid() const { return Eigen::Vector3d(x, y, z) / weight; }
  /** About the centroid, divided by the weight. */
  Eigen::Matrix3d covariance() const {
    const Eigen::Vector3d c = centroid();
    Eigen::Matrix3d products;
    products << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return products / weight - c * c.transpose();
  }
};

}  // namespace detail
}  // namespace pcl_ddg
