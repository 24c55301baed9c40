#pragma once
/** \file
 * The part of LocalFitEstimation that depends on the input point type only: every query point's
 * neighbours gathered (in parallel, in space-filling order) and handed to a fit, and the spanning
 * tree's neighbour graph. The estimators are compiled for PCL's 18 x 6 pairs of input and output
 * types; this is compiled once per input type (src/features/neighbourhood_fits.cpp), and the fit,
 * which writes the output type, is called through a std::function (one indirect call per point,
 * against a fit's thousands of operations).
 */
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/search.h>

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace pcl_ddg {
namespace detail {

/** What a fit made of one neighbourhood. */
enum class FitOutcome { Fitted, FellBack, Failed };

/** Fits one query point: neighbours' first count columns are its finite neighbours minus its
 *  position (count may be below 3, and the position non-finite: the fit then fails), found's
 *  first count entries their indices in the search surface, index is the query's input index
 *  and place its place in the output. Called from several threads at once. */
using NeighbourhoodFit = std::function<FitOutcome(
    const Eigen::Matrix3Xd& neighbours, int count, const pcl::Indices& found, pcl::index_t index,
    const Eigen::Vector3d& position, std::size_t place)>;

/** The type of pcl::Feature's search_method_surface_. */
template <typename PointInT>
using SurfaceSearch = std::function<int(const pcl::PointCloud<PointInT>&, std::size_t, double,
                                        pcl::Indices&, std::vector<float>&)>;

/** A pcl::Feature's neighbourhood settings, as LocalFitEstimation holds them. */
template <typename PointInT>
struct NeighbourhoodQueries {
  const pcl::PointCloud<PointInT>* input = nullptr;
  const pcl::PointCloud<PointInT>* surface = nullptr;
  const pcl::Indices* indices = nullptr;  ///< the query points (input indices)
  /** The input's (= surface's) coordinates in double, read instead of its floats; null: the
   *  floats. */
  const Eigen::Matrix3Xd* positions = nullptr;
  pcl::search::Search<PointInT>* tree = nullptr;
  const SurfaceSearch<PointInT>* search = nullptr;  ///< k or radius search of the surface
  double search_parameter = 0.0;                    ///< its k or radius
  double radius = 0.0;                              ///< > 0: a radius search
  int k = 0;                                        ///< pcl::Feature's k_
  unsigned int max_neighbours = 0;  ///< radius search: at most this many, the nearest
  unsigned int min_neighbours = 0;  ///< radius search: a ball with fewer is replaced by the k-NN
  int threads = 1;
};

struct FitCounts {
  std::int64_t failed = 0;
  std::int64_t fell_back = 0;
};

/** Calls fit for every query point, in parallel. */
template <typename PointInT>
FitCounts fitNeighbourhoods(const NeighbourhoodQueries<PointInT>& queries,
                            const NeighbourhoodFit& fit);

}  // namespace detail
}  // namespace pcl_ddg

#include "pcl_ddg/features/impl/neighbourhood_fits.hpp"

#ifndef PCL_NO_PRECOMPILE
#include <boost/preprocessor/seq/for_each.hpp>

#define PCL_DDG_NEIGHBOURHOOD_FITS(r, qualifier, T)                                    \
  qualifier template pcl_ddg::detail::FitCounts pcl_ddg::detail::fitNeighbourhoods<T>( \
      const pcl_ddg::detail::NeighbourhoodQueries<T>&, const pcl_ddg::detail::NeighbourhoodFit&);
// Compiled in the library for PCL's input types (as PCL's own estimators are).
BOOST_PP_SEQ_FOR_EACH(PCL_DDG_NEIGHBOURHOOD_FITS, extern, PCL_XYZ_POINT_TYPES)
#endif
