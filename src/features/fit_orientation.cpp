#include "pcl_ddg/features/fit_orientation.h"

// Once per PCL input type, for every estimator (PCA, quadric, robust) and output type.
BOOST_PP_SEQ_FOR_EACH(PCL_DDG_FIT_ORIENTATION, , PCL_XYZ_POINT_TYPES)
