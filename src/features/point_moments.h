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
  // Laid out so that (x, y), (xx, yy) and (xy, xz) are pairs addMoved forms in one vector each.
  double weight = 0.0, x = 0.0, y = 0.0, z = 0.0, xx = 0.0, yy = 0.0, zz = 0.0, xy = 0.0, xz = 0.0,
         yz = 0.0;

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
  /** Adds other, taken about a reference d from this one's: x - ours = (x - theirs) + d. Each
   *  sum is formed as o.xx + 2 o.x d.x + o.weight d.x d.x (and alike), left to right; the pairs are
   *  the same operations lane by lane (the wider planes add 32 of these per point and level). */
  void addMoved(const PointMoments& o, const Eigen::Vector3d& d) {
    using Pair = Eigen::Array2d;
    using PairMap = Eigen::Map<Pair>;
    using ConstPairMap = Eigen::Map<const Pair>;
    const Pair dxy(d.x(), d.y()), dyz(d.y(), d.z());
    const Pair oxy = ConstPairMap(&o.x), oyz(o.y, o.z);
    const double wdx = o.weight * d.x();
    weight += o.weight;
    PairMap(&x) += oxy + o.weight * dxy;
    z += o.z + o.weight * d.z();
    PairMap(&xx) += ConstPairMap(&o.xx) + 2.0 * oxy * dxy + o.weight * dxy * dxy;
    zz += o.zz + 2.0 * o.z * d.z() + o.weight * d.z() * d.z();
    PairMap(&xy) += ConstPairMap(&o.xy) + o.x * dyz + oyz * d.x() + wdx * dyz;
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
