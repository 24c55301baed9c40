#pragma once
/** \file
 * The PCL point types the library's templates are compiled for: what scan users have (LiDAR
 * intensity, Kinect RGBA, clouds with normals). Any other point type with x, y, z works by
 * defining PCL_NO_PRECOMPILE before including pcl_ddg's headers, as with PCL itself.
 */
#include <pcl/point_types.h>

#include <boost/preprocessor/seq/elem.hpp>
#include <boost/preprocessor/seq/for_each.hpp>
#include <boost/preprocessor/seq/for_each_product.hpp>

/** Input point types (searches and estimators). */
#define PCL_DDG_XYZ_POINT_TYPES                                                           \
  (pcl::PointXYZ)(pcl::PointXYZI)(pcl::PointXYZRGB)(pcl::PointXYZRGBA)(pcl::PointNormal)( \
      pcl::PointXYZINormal)(pcl::PointXYZRGBNormal)

/** Output point types of the normal estimators. */
#define PCL_DDG_NORMAL_POINT_TYPES \
  (pcl::Normal)(pcl::PointNormal)(pcl::PointXYZINormal)(pcl::PointXYZRGBNormal)
