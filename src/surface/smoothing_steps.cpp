#include "pcl_ddg/surface/smoothing_steps.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <sstream>

#include "pcl_ddg/mesh/mesh_geometry.h"

namespace pcl_ddg {

void chooseOperator(MeshSmoothingParameters& p, const std::string& weights,
                    const std::string& average, bool areas_asked) {
  const auto bad = [](const std::string& what) { throw pcl::BadArgumentException(what); };
  if (!weights.empty() && weights != "cotan" && weights != "uniform" && weights != "umbrella")
    bad("unknown weights '" + weights + "' (cotan, uniform or umbrella)");
  if (!average.empty() && average != "area" && average != "degree")
    bad("unknown average '" + average + "' (area or degree)");
  const bool implicit = p.scheme == SmoothingScheme::Implicit;
  const std::string w = !weights.empty() ? weights : implicit || areas_asked ? "cotan" : "umbrella";
  const bool by_degree = average.empty()
                             ? w == "umbrella" || (weights.empty() && !implicit && !areas_asked)
                             : average == "degree";
  if (w == "umbrella" && !by_degree) bad("the umbrella weights are averaged by degree");
  if (areas_asked && by_degree)
    bad("vertex areas average the flow by area, not by degree (drop them, or average by area)");
  p.weights = w == "cotan" ? LaplacianWeights::Cotangent : LaplacianWeights::Uniform;
  p.average = by_degree ? FlowAverage::Degree : FlowAverage::Area;
}

void chooseThicknessLimit(MeshSmoothingParameters& p, std::optional<double> limit,
                          const std::string& name) {
  if (!limit) return;
  if (!(*limit >= 0.0) || !std::isfinite(*limit))
    throw pcl::BadArgumentException(name + " must be >= 0 (0: none)");
  if (*limit > 0.0 && (p.scheme == SmoothingScheme::Taubin || p.average == FlowAverage::Degree))
    throw pcl::BadArgumentException(
        name +
        " is for area-averaged explicit and implicit steps (Taubin's filter and degree-averaged "
        "steps have no time in length^2)");
  p.thickness_limit = *limit;
}

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
  r.unit_name = !per_area ? "" : steps.absolute_time ? " length^2" : " h^2";
  if (p.scheme == SmoothingScheme::Implicit) {
    p.time_step = steps.step.value_or(1.0) * r.unit;
    return r;
  }
  r.bound = explicitStabilityLimit(topology, positions, p.weights, p.mass, p.average) / r.unit;
  // Taubin's lambda has its default; the flow's is half the bound.
  const double lambda = taubin || steps.step ? steps.step.value_or(0.5) : 0.5 * r.bound;
  p.time_step = lambda * r.unit;
  p.taubin_mu = steps.mu * r.unit;
  const double k_max = 2.0 / r.bound;  // see the header
  const double gain = taubin ? (1.0 - lambda * k_max) * (1.0 - steps.mu * k_max) : 0.0;
  r.unstable = taubin ? gain < -1.0 : lambda > r.bound;
  if (r.unstable && !steps.allow_unstable) {
    std::ostringstream what;
    if (taubin) {
      what << "the Taubin steps " << lambda << r.unit_name << " and " << steps.mu << r.unit_name
           << " multiply the finest wrinkles the stability bound " << r.bound << r.unit_name
           << " allows by " << gain;
    } else {
      what << "the explicit step " << lambda << r.unit_name << " exceeds the stability bound "
           << r.bound << r.unit_name;
    }
    what << ": the surface would blow up (" << steps.remedy << ")";
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
