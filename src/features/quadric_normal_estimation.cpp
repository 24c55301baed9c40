#include "pcl_ddg/features/quadric_normal_estimation.h"

#include "estimator_instantiation.h"
#include "pcl_ddg/features/impl/quadric_normal_estimation.hpp"

// Slice 0 of PCL's input types x every output type (estimator_instantiation.h); the other
// slices are in the other quadric_normal_estimation*.cpp files.
#define PCL_DDG_INSTANTIATE_ESTIMATOR PCL_DDG_INSTANTIATE_QuadricNormalEstimation
PCL_DDG_INSTANTIATE_ESTIMATOR_SLICE(0)
