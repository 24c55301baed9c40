#include "pcl_ddg/mesh/local_cloud.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <limits>
#include <string>

namespace pcl_ddg {

Eigen::Vector3d localOrigin(const PositionsRef& positions) {
  Eigen::AlignedBox3d bounds;
  for (Eigen::Index i = 0; i < positions.cols(); ++i)
    if (positions.col(i).allFinite()) bounds.extend(positions.col(i));
  return localOrigin(bounds);
}

Eigen::Vector3d localOrigin(const Eigen::AlignedBox3d& bounds) {
  if (bounds.isEmpty()) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d& low = bounds.min();
  const Eigen::Vector3d& high = bounds.max();
  const double side = (high - low).maxCoeff();
  // Halves, not (low + high) / 2: the sum of two coordinates near DBL_MAX would overflow.
  const Eigen::Vector3d centre = low / 2 + high / 2;
  if (side == 0.0) return centre;  // one place: x - centre is 0, exactly
  const double step = std::exp2(std::ceil(std::log2(side)));
  Eigen::Vector3d origin;
  for (int d = 0; d < 3; ++d) {
    const bool near_zero = low[d] < step && high[d] > -step;
    origin[d] = near_zero ? 0.0 : std::round(centre[d] / step) * step;
  }
  return origin;
}

LocalCloud makeLocalCloud(const PositionsRef& positions, const Eigen::Vector3d& origin,
                          std::uint32_t width) {
  auto relative = std::make_shared<Eigen::Matrix3Xd>(positions.colwise() - origin);
  auto points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  points->resize(relative->cols());
  for (Eigen::Index i = 0; i < relative->cols(); ++i) {
    const auto p = relative->col(i);
    if (p.allFinite() && p.cwiseAbs().maxCoeff() > std::numeric_limits<float>::max())
      throw pcl::BadArgumentException("point " + std::to_string(i) +
                                      " lies beyond float's range from the others (PCL's "
                                      "point types are float)");
    (*points)[i].getVector3fMap() = p.cast<float>();
  }
  points->is_dense = relative->allFinite();
  if (width > 0) {
    if (points->size() % width != 0)
      throw pcl::BadArgumentException("an organized cloud's rows must hold all of its points");
    points->width = width;
    points->height = static_cast<std::uint32_t>(points->size() / width);
  }
  LocalCloud cloud;
  cloud.points = std::move(points);
  cloud.positions = std::move(relative);
  cloud.origin = origin;
  return cloud;
}

}  // namespace pcl_ddg
