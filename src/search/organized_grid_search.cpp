#include "pcl_ddg/search/organized_grid_search.h"

#include "pcl_ddg/point_types.h"

#include "pcl_ddg/search/impl/organized_grid_search.hpp"

// Every input type of pcl_ddg/point_types.h.
#define PCL_DDG_INSTANTIATE(r, data, T) PCL_DDG_INSTANTIATE_OrganizedGridSearch(T)
BOOST_PP_SEQ_FOR_EACH(PCL_DDG_INSTANTIATE, _, PCL_DDG_XYZ_POINT_TYPES)
