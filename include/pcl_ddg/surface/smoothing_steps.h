#pragma once
/** \file
 * Smoothing operators and steps as pcl_ddg_smooth, pcl_ddg.smooth and the viewer take them: the
 * operator by name with the tools' defaults, and steps relative to the mesh so that one command
 * line works on any scan. A step averaged by area (FlowAverage::Area) is in units of h^2 (h =
 * mean edge length; length^2 with absolute_time), one averaged by degree has no unit.
 * Defaults: implicit 1, explicit half the stability bound, Taubin lambda 0.5 and mu -0.53.
 *
 * Stability of explicit steps: the eigenvalues k of -A^-1 L lie in [0, k_max], k_max = 2 / bound
 * (explicitStabilityLimit). A step tau multiplies each frequency by 1 - tau k, so tau <= bound
 * keeps |1 - tau k| <= 1. A Taubin iteration multiplies it by f(k) = (1 - lambda k)(1 - mu k):
 * f(0) = 1, a maximum a little above 1 in the pass band (Taubin's design), and then f falls, so
 * the iteration is stable when f(k_max) >= -1.
 */
#include <optional>
#include <string>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace pcl_ddg {

/**
 * Sets p.weights and p.average from their names ("cotan", "uniform", "umbrella"; "area",
 * "degree"), empty for the default: cotan weights averaged by area for the implicit scheme and
 * whenever vertex areas are asked for (areas_asked: the tools' -area), else the umbrella operator
 * (uniform weights averaged by degree), stable up to a step of 1 whatever the triangles' areas.
 * "umbrella" is uniform averaged by degree. Throws pcl::BadArgumentException for an unknown name,
 * umbrella averaged by area, or areas asked for with a degree average.
 */
void chooseOperator(MeshSmoothingParameters& p, const std::string& weights,
                    const std::string& average, bool areas_asked);

/**
 * Sets p.thickness_limit to the caller's limit (none: the default, which applies only to
 * area-averaged explicit and implicit steps). Throws pcl::BadArgumentException, naming the option
 * as the caller spells it (name), for a negative or non-finite limit, or a positive one given with
 * Taubin's filter or a degree average (their steps have no time in length^2). Call it after
 * chooseOperator.
 */
void chooseThicknessLimit(MeshSmoothingParameters& p, std::optional<double> limit,
                          const std::string& name);

struct RelativeSteps {
  std::optional<double> step;   ///< lambda_dt (Taubin: lambda); none: the default
  double mu = -0.53;            ///< Taubin's second step
  bool absolute_time = false;   ///< area-averaged steps in length^2 instead of h^2
  bool allow_unstable = false;  ///< explicit and Taubin: allow steps beyond the stability bound
  /** What an unstable step's error suggests, in the caller's words (option names). */
  std::string remedy = "use the implicit method for large steps, or allow unstable steps";
};

struct ResolvedSteps {
  double unit = 1.0;           ///< length^2 per unit of the steps (h^2, or 1)
  const char* unit_name = "";  ///< " h^2", " length^2", or "" (averaged by degree)
  double bound = 0.0;          ///< explicit and Taubin: explicitStabilityLimit in the unit; else 0
  bool unstable = false;       ///< a step beyond the bound (allowed: allow_unstable)
};

/**
 * Sets p.time_step (and p.taubin_mu) from steps on this mesh, p's scheme, weights, mass and
 * average chosen. Throws pcl::BadArgumentException for a step that is not finite and positive,
 * absolute_time with a degree average, a mesh without an edge of positive length, or (unless
 * allow_unstable) explicit or Taubin steps beyond the stability bound (see above), naming the
 * steps and the bound in their unit and ending with steps.remedy. Taubin's mu is checked by
 * smoothMeshPositions.
 */
ResolvedSteps resolveSteps(const MeshTopology& topology, const PositionsRef& positions,
                           const RelativeSteps& steps, MeshSmoothingParameters& p);

/** "explicit step 0.5 (averaged by degree); stability bound 1" and the like, for a log. */
std::string describeSteps(const MeshSmoothingParameters& p, const ResolvedSteps& resolved);

}  // namespace pcl_ddg
