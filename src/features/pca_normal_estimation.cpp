#include "pcl_ddg/features/pca_normal_estimation.h"

#include "pcl_ddg/point_types.h"

#include "pcl_ddg/features/impl/pca_normal_estimation.hpp"

// Every input type x every output type of pcl_ddg/point_types.h.
#define PCL_DDG_INSTANTIATE_PAIR(r, types) \
  PCL_DDG_INSTANTIATE_PCANormalEstimation(BOOST_PP_SEQ_ELEM(0, types), BOOST_PP_SEQ_ELEM(1, types))
BOOST_PP_SEQ_FOR_EACH_PRODUCT(PCL_DDG_INSTANTIATE_PAIR,
                              (PCL_DDG_XYZ_POINT_TYPES)(PCL_DDG_NORMAL_POINT_TYPES))
