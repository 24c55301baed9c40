#pragma once
/** \file
 * Smoothing steps given relative to the mesh, as pcl_ddg_smooth and pcl_ddg.smooth take them, so
 * that one command line works on any scan: a step averaged by area (FlowAverage::Area) in units of
 * h^2 (h = mean edge length; length^2 with absolute_time), one averaged by degree without unit.
 * Defaults: implicit 1, explicit half the stability bound, Taubin lambda 0.5 and mu -0.53.
 */
#include <optional>
#include <string>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace pcl_ddg {

struct RelativeSteps {
  std::optional<double> step;   ///< lambda_dt (Taubin: lambda); none: the default
  double mu = -0.53;            ///< Taubin's second step
  bool absolute_time = false;   ///< area-averaged steps in length^2 instead of h^2
  bool allow_unstable = false;  ///< explicit and Taubin: allow steps above the stability bound
};

struct ResolvedSteps {
  double unit = 1.0;           ///< length^2 per unit of the steps (h^2, or 1)
  const char* unit_name = "";  ///< " h^2", or "" (degree-averaged, or absolute time)
  double bound = 0.0;          ///< explicit and Taubin: explicitStabilityLimit in the unit; else 0
  bool unstable = false;       ///< a step above the bound (allowed: allow_unstable)
};

/**
 * Sets p.time_step (and p.taubin_mu) from steps on this mesh, p's scheme, weights, mass and
 * average chosen. Throws pcl::BadArgumentException for a step that is not finite and positive, a
 * Taubin mu not below -lambda, absolute_time with a degree average, a mesh without an edge of
 * positive length, or (unless allow_unstable) an explicit or Taubin step above the stability
 * bound, naming the step and the bound in their unit.
 */
ResolvedSteps resolveSteps(const MeshTopology& topology, const PositionsRef& positions,
                           const RelativeSteps& steps, MeshSmoothingParameters& p);

/** "explicit step 0.5 (averaged by degree); stability bound 1" and the like, for a log. */
std::string describeSteps(const MeshSmoothingParameters& p, const ResolvedSteps& resolved);

}  // namespace pcl_ddg
