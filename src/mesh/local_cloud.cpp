#include "pcl_ddg/mesh/local_cloud.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <cstring>
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
  Eigen::Vector3d origin;
  for (int d = 0; d < 3; ++d) {
    const double low = bounds.min()[d], high = bounds.max()[d];
    // Halves, not (low + high) / 2: the sum of two coordinates near DBL_MAX would overflow.
    const double centre = low / 2 + high / 2;
    const double side = high - low;
    if (side == 0.0) {  // one place along this axis: x - centre is 0, exactly
      origin[d] = centre;
      continue;
    }
    const double step = std::exp2(std::ceil(std::log2(side)));
    const bool near_zero = low < step && high > -step;
    origin[d] = near_zero ? 0.0 : std::round(centre / step) * step;
  }
  return origin;
}

LocalCloud makeLocalCloud(const PositionsRef& positions, const Eigen::Vector3d& origin,
                          std::uint32_t width) {
  return localCloudOf(std::make_shared<Eigen::Matrix3Xd>(positions.colwise() - origin), origin,
                      width);
}

namespace {

/** Whether floats hold a point's local coordinates exactly (beyond float's range they do not). */
bool floatsHold(const Eigen::Vector3d& relative) {
  return floatHolds(relative.x()) && floatHolds(relative.y()) && floatHolds(relative.z());
}

/** A LocalCloud of float points about origin: organized width points per row when width > 0,
 *  its sensor at the world origin. */
LocalCloud localCloudOfPoints(std::shared_ptr<pcl::PointCloud<pcl::PointXYZ>> points,
                              std::shared_ptr<Eigen::Matrix3Xd> relative,
                              const Eigen::Vector3d& origin, std::uint32_t width) {
  if (width > 0) {
    if (points->size() % width != 0)
      throw pcl::BadArgumentException("an organized cloud's rows must hold all of its points");
    points->width = width;
    points->height = static_cast<std::uint32_t>(points->size() / width);
  }
  // PCL's default sensor, the origin, where it lies in the local frame (organized clouds measure
  // ranges from it); a caller who knows the sensor sets its own.
  points->sensor_origin_.head<3>() = (-origin).cast<float>();
  LocalCloud cloud;
  cloud.points = std::move(points);
  cloud.positions = std::move(relative);
  cloud.origin = origin;
  return cloud;
}

}  // namespace

LocalCloud localCloudOfFloats(const std::uint8_t* rows, std::size_t stride,
                              const std::uint32_t offsets[3], std::size_t count,
                              const Eigen::Vector3d& origin, std::uint32_t width) {
  auto points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  points->resize(count);
  bool dense = true;
  for (std::size_t i = 0; i < count; ++i) {
    Eigen::Vector3d world;
    for (int d = 0; d < 3; ++d) {
      float value;
      std::memcpy(&value, rows + i * stride + offsets[d], sizeof value);
      world[d] = value;
    }
    Eigen::Vector3d relative;
    for (int d = 0; d < 3; ++d) relative[d] = localCoordinate(world[d], origin[d]);
    if (!world.allFinite())
      dense = false;
    else if (!floatsHold(relative))
      return LocalCloud();
    (*points)[i].getVector3fMap() = relative.cast<float>();
  }
  points->is_dense = dense;
  return localCloudOfPoints(std::move(points), nullptr, origin, width);
}

LocalCloud localCloudOf(std::shared_ptr<Eigen::Matrix3Xd> relative, const Eigen::Vector3d& origin,
                        std::uint32_t width) {
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
  // Floats that hold the positions exactly (a float file's, data near the origin) are what the
  // fits read: the doubles would only cost memory and a second read per neighbour.
  bool exact = true;
  for (Eigen::Index i = 0; i < relative->cols() && exact; ++i)
    exact = floatsHold(relative->col(i)) || !relative->col(i).allFinite();
  if (exact) relative.reset();
  return localCloudOfPoints(std::move(points), std::move(relative), origin, width);
}

}  // namespace pcl_ddg
