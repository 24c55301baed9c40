#include "pcl_ddg/surface/scalar_field_smoothing.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <string>

#include "laplacian_flow.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {

Eigen::MatrixXd smoothScalarFields(const MeshTopology& topology, const PositionsRef& positions,
                                   const Eigen::MatrixXd& fields, const HeatFlowParameters& p) {
  const int n = topology.numVertices();
  if (n == 0 || topology.numTriangles() == 0) throw InvalidMeshException("mesh has no triangles");
  if (positions.cols() != n) throw InvalidMeshException("positions do not match the mesh");
  requireFinite(positions);
  const auto bad = [](const std::string& what) { throw pcl::BadArgumentException(what); };
  if (fields.rows() != n)
    bad("the field has " + std::to_string(fields.rows()) + " values for " + std::to_string(n) +
        " vertices");
  if (!(p.diffusion_time > 0.0) || !std::isfinite(p.diffusion_time))
    bad("diffusion time must be > 0");
  if (p.iterations < 1) bad("iterations must be at least 1");
  if (p.scheme == SmoothingScheme::Taubin) bad("heat flow is explicit or implicit, not Taubin");

  const Eigen::VectorXd mass = lumpedMass(topology, positions, p.mass);
  // Massless vertices keep their values (NaN allowed there); they take no part in the flow.
  Eigen::MatrixXd values = fields;
  std::int64_t first_bad = -1, bad_count = 0;
  for (int v = 0; v < n; ++v) {
    if (values.row(v).allFinite()) continue;
    if (mass[v] > 0.0) {
      if (first_bad < 0) first_bad = v;
      ++bad_count;
    }
    values.row(v).setZero();
  }
  if (bad_count > 0) {
    bad("vertex " + std::to_string(first_bad) + " has a non-finite value (" +
        std::to_string(bad_count) + " such vertices)");
  }

  std::vector<char> fixed(n, 0);
  if (p.boundary == BoundaryCondition::Fixed) {
    for (int v = 0; v < n; ++v) fixed[v] = topology.isBoundary(v);
  }
  detail::LaplacianFlow flow(n, std::move(fixed), p.solver, p.implicit_solver);
  flow.planSteps(p.iterations, 1);
  flow.setOperator(laplacian(topology, positions, p.weights, LaplacianForm::Summed), mass);
  const double tau = p.diffusion_time / p.iterations;
  for (int iteration = 1; iteration <= p.iterations; ++iteration) {
    if (p.scheme == SmoothingScheme::Explicit) {
      flow.explicitStep(values, tau);
    } else {
      flow.implicitStep(values, tau);
    }
    if (!values.allFinite()) {
      throw pcl::ComputeFailedException(
          "heat flow step " + std::to_string(iteration) +
          ": non-finite values (the explicit step is unstable: use more iterations or the "
          "implicit scheme)");
    }
  }
  for (int v = 0; v < n; ++v) {
    if (!(mass[v] > 0.0)) values.row(v) = fields.row(v);
  }
  return values;
}

Eigen::VectorXd smoothScalarField(const MeshTopology& topology, const PositionsRef& positions,
                                  const Eigen::VectorXd& field, const HeatFlowParameters& p) {
  return smoothScalarFields(topology, positions, field, p);
}

}  // namespace pcl_ddg
