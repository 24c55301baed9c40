// Mesh functions: normals, Laplacian, mass, curvatures, report, smoothing. Each builds the topology
// from F and calls the library as the tools do, with the GIL released.
#include <pcl/exceptions.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <optional>

#include "binding_common.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/operators/laplacian.h"
#include "pcl_ddg/operators/mass_matrix.h"
#include "pcl_ddg/result_warnings.h"
#include "pcl_ddg/surface/mesh_normals.h"
#include "pcl_ddg/surface/mesh_smoothing.h"
#include "pcl_ddg/surface/scalar_field_smoothing.h"
#include "pcl_ddg/surface/smoothing_steps.h"

namespace pcl_ddg {
namespace python {

namespace {

// V (read in place where it can be) and F as the library takes them; V must be finite
// (InvalidMeshError naming the vertex).
struct Mesh {
  PositionsView positions;
  MeshTopology topology;
};

Mesh meshOf(const py::array& vertices, const py::object& faces,
            NonFinitePolicy finite = NonFinitePolicy::Throw,
            OutOfRangeFacePolicy policy = OutOfRangeFacePolicy::Throw) {
  PositionsView positions(vertices, "V");
  if (finite == NonFinitePolicy::Throw) {
    py::gil_scoped_release release;
    requireFinite(positions.map());
  }
  MeshTopology topology = topologyOf(static_cast<int>(positions.cols()), faces, policy);
  return {std::move(positions), std::move(topology)};
}

MassType massOf(const std::string& kind) {
  return chooseMassType(kind, "mass", kPythonStyle);
}

LaplacianWeights weightsOf(const std::string& weights) {
  return choice("weights", weights, {"cotan", "uniform"}) == "uniform"
             ? LaplacianWeights::Uniform
             : LaplacianWeights::Cotangent;
}

SolverChoice solverOf(const std::string& solver) {
  return chooseSolver(solver, kPythonStyle);
}

SmoothingScheme schemeOf(const std::string& method) {
  return choice("method", method, {"implicit", "explicit"}) == "explicit"
             ? SmoothingScheme::Explicit
             : SmoothingScheme::Implicit;
}

// Ctrl-C between smoothing steps: the handler runs, and its KeyboardInterrupt unwinds the run.
void checkSignals(int, int) {
  py::gil_scoped_acquire acquire;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

}  // namespace

void bindMeshes(py::module_& m) {
  m.def(
      "vertex_normals",
      [](const py::array& V, const py::object& F, const std::string& weights,
         std::optional<double> epsilon, const std::string& mass) {
        MeshNormalOptions options;
        options.weighting = chooseNormalWeighting(weights, "weights", kPythonStyle);
        if (epsilon) {
          if (options.weighting != NormalWeighting::MeanCurvature)
            throw py::value_error("epsilon applies to weights='mean_curvature' only");
          if (!(*epsilon >= 0.0) || !std::isfinite(*epsilon))
            throw py::value_error("epsilon must be >= 0");
          options.epsilon = *epsilon;
        }
        options.mass = massOf(mass);
        Mesh mesh = meshOf(V, F);
        MeshNormals normals = compute(
            [&] { return computeMeshNormals(mesh.topology, mesh.positions.map(), options); });
        py::dict counts;
        counts["invalid_vertices"] = normals.invalid_vertices;
        counts["cancelled_vertices"] = normals.cancelled_vertices;
        counts["fallback_vertices"] = normals.fallback_vertices;
        counts["warnings"] = meshNormalWarnings(normals, options.weighting);
        return py::make_tuple(rowsArray(std::move(normals.normals)), maskArray(normals.valid),
                              counts);
      },
      py::arg("V"), py::arg("F"), py::arg("weights") = "area", py::arg("epsilon") = py::none(),
      py::arg("mass") = "mixed", "(normals, valid, counts) of computeMeshNormals.");

  m.def(
      "laplacian",
      [](const py::array& V, const py::object& F, const std::string& weights,
         const std::string& form, const std::string& mass) {
        const LaplacianWeights w = weightsOf(weights);
        const LaplacianForm f = choice("form", form, {"summed", "averaged"}) == "averaged"
                                    ? LaplacianForm::Averaged
                                    : LaplacianForm::Summed;
        const MassType type = massOf(mass);
        Mesh mesh = meshOf(V, F);
        // Compressed rows straight from the library: the arrays are scipy's CSR as they are,
        // kept alive by one capsule.
        auto* matrix = new Eigen::SparseMatrix<double, Eigen::RowMajor>(compute([&] {
          return laplacian<Eigen::RowMajor>(mesh.topology, mesh.positions.map(), w, f, type);
        }));
        py::capsule owner(matrix, [](void* p) {
          delete static_cast<Eigen::SparseMatrix<double, Eigen::RowMajor>*>(p);
        });
        const auto nnz = static_cast<py::ssize_t>(matrix->nonZeros());
        const auto rows = static_cast<py::ssize_t>(matrix->outerSize());
        return py::make_tuple(py::array_t<double>({nnz}, matrix->valuePtr(), owner),
                              py::array_t<int>({nnz}, matrix->innerIndexPtr(), owner),
                              py::array_t<int>({rows + 1}, matrix->outerIndexPtr(), owner));
      },
      py::arg("V"), py::arg("F"), py::arg("weights") = "cotan", py::arg("form") = "summed",
      py::arg("mass") = "mixed", "(data, indices, indptr) of L in CSR form.");

  m.def(
      "mass_matrix",
      [](const py::array& V, const py::object& F, const std::string& mass) {
        const MassType type = massOf(mass);
        Mesh mesh = meshOf(V, F);
        return vectorArray(
            compute([&] { return lumpedMass(mesh.topology, mesh.positions.map(), type); }));
      },
      py::arg("V"), py::arg("F"), py::arg("mass") = "mixed", "The diagonal of M (vertex areas).");

  m.def(
      "curvatures",
      [](const py::array& V, const py::object& F, const std::string& mass) {
        const MassType type = massOf(mass);
        Mesh mesh = meshOf(V, F);
        VertexCurvatures c =
            compute([&] { return computeCurvatures(mesh.topology, mesh.positions.map(), type); });
        py::dict counts;
        counts["clamped_vertices"] = c.clamped_vertices;
        counts["invalid_vertices"] = c.invalid_vertices;
        counts["unoriented_vertices"] = c.unoriented_vertices;
        counts["warnings"] = curvatureWarnings(c);
        return py::make_tuple(vectorArray(std::move(c.mean_curvature)),
                              vectorArray(std::move(c.gauss_curvature)),
                              vectorArray(std::move(c.k1)), vectorArray(std::move(c.k2)),
                              vectorArray(std::move(c.vertex_area)), maskArray(c.valid), counts);
      },
      py::arg("V"), py::arg("F"), py::arg("mass") = "mixed",
      "(mean, gauss, k1, k2, area, valid, counts) of computeCurvatures.");

  m.def(
      "mesh_report",
      [](const py::array& V, const py::object& F) {
        // As pcl_ddg_info: defects are counted, not refused.
        Mesh mesh = meshOf(V, F, NonFinitePolicy::Keep, OutOfRangeFacePolicy::Drop);
        return compute(
            [&] { return makeMeshReport(mesh.topology, mesh.positions.map()).toJson(); });
      },
      py::arg("V"), py::arg("F"), "makeMeshReport as JSON (pcl_ddg_info -json).");

  m.def(
      "smooth",
      [](const py::array& V, const py::object& F, const std::string& method,
         std::optional<std::string> weights, std::optional<std::string> average,
         std::optional<std::string> mass, std::optional<double> lambda_dt,
         std::optional<double> lambda_, std::optional<double> mu, int iterations,
         bool absolute_time, bool freeze_weights, bool update_mass, bool rebuild_weights,
         std::optional<double> thickness_limit, bool fix_boundary, bool allow_unstable,
         const std::string& preserve, const std::string& solver) {
        // pcl_ddg_smooth's options and defaults (tools/pcl_ddg_smooth.cpp).
        MeshSmoothingParameters p;
        const std::string scheme = choice("method", method, {"implicit", "explicit", "taubin"});
        p.scheme = scheme == "explicit" ? SmoothingScheme::Explicit
                   : scheme == "taubin" ? SmoothingScheme::Taubin
                                        : SmoothingScheme::Implicit;
        try {
          chooseOperator(p, weights.value_or(""), average.value_or(""), mass.has_value());
        } catch (const pcl::BadArgumentException& e) {
          throw py::value_error(errorDescription(e));
        }
        p.mass = massOf(mass.value_or("mixed"));
        if (iterations < 1) throw py::value_error("iterations must be at least 1");
        p.iterations = iterations;
        if (freeze_weights + update_mass + rebuild_weights > 1)
          throw py::value_error(
              "freeze_weights, update_mass and rebuild_weights exclude each other");
        if (update_mass) p.weight_update = WeightUpdate::FrozenStiffness;
        if (rebuild_weights) p.weight_update = WeightUpdate::EveryIteration;
        try {
          chooseThicknessLimit(p, thickness_limit, "thickness_limit");
        } catch (const pcl::BadArgumentException& e) {
          throw py::value_error(errorDescription(e));
        }
        if (fix_boundary) p.boundary = BoundaryCondition::Fixed;
        const std::string keep = choice("preserve", preserve, {"none", "volume", "area"});
        p.shrinkage = keep == "volume" ? ShrinkageCorrection::PreserveVolume
                      : keep == "area" ? ShrinkageCorrection::PreserveArea
                                       : ShrinkageCorrection::None;
        const SolverChoice s = solverOf(solver);
        p.implicit_solver = s.method;
        p.solver = s.backend;
        const bool taubin = p.scheme == SmoothingScheme::Taubin;
        if (taubin && lambda_dt)
          throw py::value_error("method='taubin' takes lambda_ and mu, not lambda_dt");
        if (!taubin && (lambda_ || mu))
          throw py::value_error("lambda_ and mu are method='taubin''s (the flow takes lambda_dt)");
        RelativeSteps steps;
        steps.step = taubin ? lambda_ : lambda_dt;
        steps.mu = mu.value_or(steps.mu);
        steps.remedy =
            "method='implicit' for large steps, weights='umbrella', or allow_unstable=True";
        steps.absolute_time = absolute_time;
        steps.allow_unstable = allow_unstable;
        if (absolute_time && !steps.step)
          throw py::value_error(taubin ? "absolute_time needs lambda_"
                                       : "absolute_time needs lambda_dt");
        Mesh mesh = meshOf(V, F);
        Eigen::Matrix3Xd smoothed = compute([&] {
          resolveSteps(mesh.topology, mesh.positions.map(), steps, p);
          return smoothMeshPositions(mesh.topology, Eigen::Matrix3Xd(mesh.positions.map()), p,
                                     nullptr, checkSignals);
        });
        return rowsArray(std::move(smoothed));
      },
      py::arg("V"), py::arg("F"), py::arg("method") = "implicit", py::arg("weights") = py::none(),
      py::arg("average") = py::none(), py::arg("mass") = "mixed", py::arg("lambda_dt") = py::none(),
      py::arg("lambda_") = py::none(), py::arg("mu") = -0.53, py::arg("iterations") = 1,
      py::arg("absolute_time") = false, py::arg("freeze_weights") = false,
      py::arg("update_mass") = false, py::arg("rebuild_weights") = false,
      py::arg("thickness_limit") = py::none(), py::arg("fix_boundary") = false,
      py::arg("allow_unstable") = false, py::arg("preserve") = "none", py::arg("solver") = "auto",
      "smoothMeshPositions with pcl_ddg_smooth's options.");

  m.def(
      "smooth_field",
      [](const py::array& V, const py::object& F, const py::array& values, double time,
         const std::string& method, const std::string& weights, const std::string& mass,
         int iterations, bool absolute_time, bool fix_boundary, const std::string& solver) {
        HeatFlowParameters p;
        p.scheme = schemeOf(method);
        p.weights = weightsOf(weights);
        p.mass = massOf(mass);
        if (iterations < 1) throw py::value_error("iterations must be at least 1");
        p.iterations = iterations;
        if (fix_boundary) p.boundary = BoundaryCondition::Fixed;
        const SolverChoice s = solverOf(solver);
        p.implicit_solver = s.method;
        p.solver = s.backend;
        if (!(time > 0.0) || !std::isfinite(time)) throw py::value_error("time must be > 0");
        const char kind = values.dtype().kind();
        if (kind != 'f' && kind != 'i' && kind != 'u')
          throw py::value_error("values must hold real numbers");
        if (values.ndim() != 1 && values.ndim() != 2)
          throw py::value_error("values must have shape (n,) or (n, c)");
        Mesh mesh = meshOf(V, F);
        if (values.shape(0) != mesh.positions.cols())
          throw py::value_error("values has " + std::to_string(values.shape(0)) +
                                " rows for a mesh of " + std::to_string(mesh.positions.cols()) +
                                " vertices");
        // Fields in columns (N x c, column-major): NumPy's Fortran order, converted once.
        const auto input =
            py::array_t<double, py::array::f_style | py::array::forcecast>::ensure(values);
        const Eigen::Index columns = values.ndim() == 2 ? values.shape(1) : 1;
        const Eigen::Map<const Eigen::MatrixXd> fields(input.data(), mesh.positions.cols(),
                                                       columns);
        auto* result = new Eigen::MatrixXd();
        py::capsule owner(result, [](void* p) { delete static_cast<Eigen::MatrixXd*>(p); });
        *result = compute([&] {
          const double h = meanEdgeLength(mesh.topology, mesh.positions.map());
          if (!(h > 0.0))
            throw pcl::BadArgumentException("the mesh has no edge of positive length");
          p.diffusion_time = absolute_time ? time : time * h * h;
          return smoothScalarFields(mesh.topology, mesh.positions.map(), fields, p);
        });
        const auto rows = static_cast<py::ssize_t>(result->rows());
        if (values.ndim() == 1) return py::array_t<double>({rows}, result->data(), owner);
        return py::array_t<double>(
            {rows, static_cast<py::ssize_t>(result->cols())},
            {py::ssize_t{sizeof(double)}, rows * py::ssize_t{sizeof(double)}}, result->data(),
            owner);
      },
      py::arg("V"), py::arg("F"), py::arg("values"), py::arg("time"),
      py::arg("method") = "implicit", py::arg("weights") = "cotan", py::arg("mass") = "mixed",
      py::arg("iterations") = 1, py::arg("absolute_time") = false, py::arg("fix_boundary") = false,
      py::arg("solver") = "auto", "smoothScalarFields (heat flow) with the time in units of h^2.");
}

}  // namespace python
}  // namespace pcl_ddg
