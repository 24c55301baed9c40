#include "pcl_ddg/features/neighbourhood_fits.h"

// Once per PCL input type, for every estimator (PCA, quadric, robust) and output type.
BOOST_PP_SEQ_FOR_EACH(PCL_DDG_NEIGHBOURHOOD_FITS, , PCL_XYZ_POINT_TYPES)
