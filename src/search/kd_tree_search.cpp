#include "pcl_ddg/search/kd_tree_search.h"

#include <pcl/point_types.h>

#include "pcl_ddg/search/impl/kd_tree_search.hpp"

PCL_DDG_INSTANTIATE_KdTreeSearch(pcl::PointXYZ) PCL_DDG_INSTANTIATE_KdTreeSearch(pcl::PointXYZRGB)
    PCL_DDG_INSTANTIATE_KdTreeSearch(pcl::PointXYZI)
        PCL_DDG_INSTANTIATE_KdTreeSearch(pcl::PointNormal)
            PCL_DDG_INSTANTIATE_KdTreeSearch(pcl::PointXYZRGBNormal)
