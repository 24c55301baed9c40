#include "pcl_ddg/search/mesh_ring_search.h"

#include <pcl/point_types.h>

#include "pcl_ddg/search/impl/mesh_ring_search.hpp"

PCL_DDG_INSTANTIATE_MeshRingSearch(pcl::PointXYZ)
    PCL_DDG_INSTANTIATE_MeshRingSearch(pcl::PointXYZRGB)
        PCL_DDG_INSTANTIATE_MeshRingSearch(pcl::PointXYZI)
            PCL_DDG_INSTANTIATE_MeshRingSearch(pcl::PointNormal)
                PCL_DDG_INSTANTIATE_MeshRingSearch(pcl::PointXYZRGBNormal)
