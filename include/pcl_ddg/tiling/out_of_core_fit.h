#pragma once
/** \file
 * The fitted estimators on a cloud file larger than memory: the file is read a piece at a time,
 * cut into tiles (tile_plan.h), each tile fitted with its halo (tiled_local_fit.h), and the
 * output written in the input's order with every input field and the new ones, so that the result
 * equals the in-memory one value for value. Memory stays within a budget whatever the file's size:
 *   1. a pass over the file for the bounds, a second for the point histogram the plan is cut from
 *   2. a third writes every finite point (index, x, y, z) into its tile's file in a scratch folder
 *      (beside plan.json: each tile can then be fitted by an independent worker)
 *   3. each tile is gathered from the tile files its halo touches, fitted, and its results are
 *      written at their points' places in a results file
 *   4. a last pass joins the input's pieces and the results into the output
 * Input: what io/cloud_pieces.h reads in pieces (binary PCD, binary PLY, LAS). Output: binary PCD
 * or binary PLY, by extension.
 */
#include <pcl/PCLPointCloud2.h>

#include <cstdint>
#include <functional>
#include <string>

#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/io/cloud_pieces.h"
#include "pcl_ddg/tiling/tiled_local_fit.h"

namespace pcl_ddg {

struct OutOfCoreOptions {
  std::uint64_t memory_budget = std::uint64_t{2} << 30;  ///< bytes, for everything held at once
  std::string scratch_folder;  ///< where the tile files go; empty: beside the output
};

struct OutOfCoreReport {
  std::int64_t points = 0;
  std::int64_t failed_points = 0;  ///< as LocalFitResult
  std::int64_t fallback_points = 0;
  std::int64_t points_per_tile = 0;   ///< the limit the budget gave
  std::int64_t points_per_piece = 0;  ///< read at once in the streaming passes
  TilingReport tiling;
  SensorPose sensor_pose;  ///< the input's VIEWPOINT (PCD)
};

/** Adds the fit's fields to a piece of the input (the fit has one entry per point of the piece):
 *  the caller's output convention, the same as for a cloud in memory. */
using ResultFields = std::function<void(CloudPiece& piece, const LocalFitResult& fit)>;

/**
 * Fits options' estimator to every point of the cloud file `input` and writes `output`. The
 * viewpoint, if unset, is the input's VIEWPOINT. Throws FileFormatException for inputs that
 * cannot be read in pieces, pcl::BadArgumentException for options that need the whole cloud
 * (mesh rings) or a budget too small for a tile.
 */
OutOfCoreReport fitCloudFileOutOfCore(const std::string& input, const std::string& output,
                                      LocalFitOptions options, const OutOfCoreOptions& limits,
                                      const ResultFields& add_fields);

}  // namespace pcl_ddg
