#include "pcl_ddg/features/robust_normal_estimation.h"

#include "estimator_instantiation.h"
#include "pcl_ddg/features/impl/robust_normal_estimation.hpp"

// Every input type x every output type (estimator_instantiation.h), in one file: the per-type
// code is the fit's call, the fit itself (robust_plane_fit.cpp) is compiled once.
#define PCL_DDG_INSTANTIATE_ESTIMATOR PCL_DDG_INSTANTIATE_RobustNormalEstimation
PCL_DDG_INSTANTIATE_ESTIMATOR_SLICE(0)
PCL_DDG_INSTANTIATE_ESTIMATOR_SLICE(1)
PCL_DDG_INSTANTIATE_ESTIMATOR_SLICE(2)
