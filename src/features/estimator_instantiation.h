#pragma once
// The point types the normal estimators are compiled for: the lists PCL compiles
// pcl::NormalEstimation for (PCL_XYZ_POINT_TYPES x PCL_NORMAL_POINT_TYPES, 18 x 6 = 108 pairs in
// PCL 1.13), so that every pair that links with PCL's estimator links with ours without
// PCL_NO_PRECOMPILE. The input types are cut into PCL_DDG_ESTIMATOR_SLICES slices, one source
// file each, so that the library's slowest files compile in parallel.
#include <pcl/point_types.h>

#include <boost/preprocessor/arithmetic/div.hpp>
#include <boost/preprocessor/arithmetic/inc.hpp>
#include <boost/preprocessor/arithmetic/mul.hpp>
#include <boost/preprocessor/arithmetic/sub.hpp>
#include <boost/preprocessor/seq/elem.hpp>
#include <boost/preprocessor/seq/for_each_product.hpp>
#include <boost/preprocessor/seq/size.hpp>
#include <boost/preprocessor/seq/subseq.hpp>

#define PCL_DDG_ESTIMATOR_INPUT_TYPES PCL_XYZ_POINT_TYPES
#define PCL_DDG_ESTIMATOR_OUTPUT_TYPES PCL_NORMAL_POINT_TYPES
#define PCL_DDG_ESTIMATOR_SLICES 3

/** Where slice `part` of the input types starts. */
#define PCL_DDG_ESTIMATOR_SLICE_BEGIN(part)                                          \
  BOOST_PP_DIV(BOOST_PP_MUL(part, BOOST_PP_SEQ_SIZE(PCL_DDG_ESTIMATOR_INPUT_TYPES)), \
               PCL_DDG_ESTIMATOR_SLICES)
/** Input types of slice `part` (0 .. PCL_DDG_ESTIMATOR_SLICES - 1). */
#define PCL_DDG_ESTIMATOR_INPUT_SLICE(part)                                               \
  BOOST_PP_SEQ_SUBSEQ(PCL_DDG_ESTIMATOR_INPUT_TYPES, PCL_DDG_ESTIMATOR_SLICE_BEGIN(part), \
                      BOOST_PP_SUB(PCL_DDG_ESTIMATOR_SLICE_BEGIN(BOOST_PP_INC(part)),     \
                                   PCL_DDG_ESTIMATOR_SLICE_BEGIN(part)))

/** Instantiates estimator (PCL_DDG_INSTANTIATE_<estimator>(T, NT)) for slice part x every
 *  output type. */
#define PCL_DDG_INSTANTIATE_ESTIMATOR_PAIR(r, types) \
  PCL_DDG_INSTANTIATE_ESTIMATOR(BOOST_PP_SEQ_ELEM(0, types), BOOST_PP_SEQ_ELEM(1, types))
#define PCL_DDG_INSTANTIATE_ESTIMATOR_SLICE(part) \
  BOOST_PP_SEQ_FOR_EACH_PRODUCT(                  \
      PCL_DDG_INSTANTIATE_ESTIMATOR_PAIR,         \
      (PCL_DDG_ESTIMATOR_INPUT_SLICE(part))(PCL_DDG_ESTIMATOR_OUTPUT_TYPES))
