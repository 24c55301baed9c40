#include "pcl_ddg/features/pca_normal_estimation.h"

#include <pcl/point_types.h>

#include "pcl_ddg/features/impl/pca_normal_estimation.hpp"

#define PCL_DDG_INSTANTIATE_FOR_OUTPUTS(T)                                                         \
  PCL_DDG_INSTANTIATE_PCANormalEstimation(T, pcl::Normal) PCL_DDG_INSTANTIATE_PCANormalEstimation( \
      T, pcl::PointNormal) PCL_DDG_INSTANTIATE_PCANormalEstimation(T, pcl::PointXYZRGBNormal)

PCL_DDG_INSTANTIATE_FOR_OUTPUTS(pcl::PointXYZ)
PCL_DDG_INSTANTIATE_FOR_OUTPUTS(pcl::PointXYZRGB)
PCL_DDG_INSTANTIATE_FOR_OUTPUTS(pcl::PointNormal)
PCL_DDG_INSTANTIATE_FOR_OUTPUTS(pcl::PointXYZRGBNormal)
