#include "pcl_ddg/surface/smoothing_steps.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <sstream>

#include "pcl_ddg/mesh/mesh_geometry.h"

namespace pcl_ddg {

ResolvedSteps resolveSteps(const MeshTopology& topology, const PositionsRef& positions,
                           const RelativeSteps& steps, MeshSmoothingParameters& p) {
  const bool taubin = p.scheme == SmoothingScheme::Taubin;
  const bool per_area = p.average == FlowAverage::Area;
  if (steps.step && (!(*steps.step > 0.0) || !std::isfinite(*steps.step)))
    throw pcl::BadArgumentException(taubin ? "lambda must be > 0" : "lambda_dt must be > 0");
  if (steps.absolute_time && !per_area)
    throw pcl::BadArgumentException("absolute time is for steps averaged by area");
  const double h = meanEdgeLength(topology, positions);
  if (!(h > 0.0)) throw pcl::BadArgumentException("the mesh has no edge of positive length");
  ResolvedSteps r;
  r.unit = per_area && !steps.absolute_time ? h * h : 1.0;
  r.unit_name = per_area && !steps.absolute_time ? " h^2" : "";
  if (p.scheme == SmoothingScheme::Implicit) {
    p.time_step = steps.step.value_or(1.0) * r.unit;
    return r;
  }
  const double lambda = steps.step.value_or(0.5);
  if (taubin && (!(steps.mu < -lambda) || !std::isfinite(steps.mu)))
    throw pcl::BadArgumentException("mu must be below -lambda (e.g. lambda 0.5, mu -0.53)");
  r.bound = explicitStabilityLimit(topology, positions, p.weights, p.mass, p.average) / r.unit;
  // Taubin's lambda has its default; the flow's is half the bound.
  p.time_step = (taubin || steps.step ? lambda : 0.5 * r.bound) * r.unit;
  p.taubin_mu = steps.mu * r.unit;
  const double largest = taubin ? -steps.mu : p.time_step / r.unit;
  r.unstable = largest > r.bound;
  if (r.unstable && !steps.allow_unstable) {
    std::ostringstream what;
    what << "the " << (taubin ? "Taubin" : "explicit") << " step " << largest << r.unit_name
         << " exceeds the stability bound " << r.bound << r.unit_name
         << ": the surface would blow up (use the implicit method for large steps, "
         << (per_area ? "the umbrella weights, " : "") << "or allow unstable steps)";
    throw pcl::BadArgumentException(what.str());
  }
  return r;
}

std::string describeSteps(const MeshSmoothingParameters& p, const ResolvedSteps& r) {
  std::ostringstream text;
  const char* average = p.average == FlowAverage::Area ? "averaged by area" : "averaged by degree";
  if (p.scheme == SmoothingScheme::Implicit) {
    text << "implicit step " << p.time_step / r.unit << r.unit_name << " (" << average << ")";
    return text.str();
  }
  if (p.scheme == SmoothingScheme::Taubin) {
    text << "Taubin steps " << p.time_step / r.unit << r.unit_name << " and "
         << p.taubin_mu / r.unit << r.unit_name;
  } else {
    text << "explicit step " << p.time_step / r.unit << r.unit_name;
  }
  text << " (" << average << "); stability bound " << r.bound << r.unit_name;
  return text.str();
}

}  // namespace pcl_ddg
