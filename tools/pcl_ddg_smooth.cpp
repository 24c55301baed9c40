// pcl_ddg_smooth: Laplacian smoothing of a mesh's vertex positions, explicit (many small steps)
// or implicit (few large ones), with the time step in units of the squared mean edge length.
#include <pcl/exceptions.h>

#include <cmath>
#include <iostream>

#include "common/operator_options.h"
#include "common/tool_common.h"
#include "common/tool_input.h"
#include "common/tool_output.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace {

constexpr const char* kName = "pcl_ddg_smooth";
constexpr const char* kDescription =
    "Smooths a mesh by Laplacian flow dx/dt = M^-1 L x: explicit (forward Euler; stable only for\n"
    "small steps, the bound is printed) or implicit (backward Euler, one sparse Cholesky or\n"
    "conjugate-gradient solve per iteration, by default whichever costs less; any step). The time "
    "step -lambda_dt is in units of h^2 (h = mean edge length), so\n"
    "one command line works on any scan; -absolute_time takes it in length^2.";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk} output.{ply,pcd,las}\n"
    "         [-method explicit|implicit (default implicit)] [-weights uniform|cotan (default "
    "cotan)]\n"
    "         [-area mixed|voronoi|barycentric] [-lambda_dt t (default: implicit 1, explicit half "
    "the stability bound)]\n"
    "         [-iterations n (default 1)] [-absolute_time] [-freeze_weights | -rebuild_weights]\n"
    "         [-fix_boundary] [-allow_unstable]\n"
    "         [-preserve volume|area] [-solver auto|cholmod|ldlt|cg] [-precision float|double]";

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(
      argc, argv,
      {"method", "weights", "area", "mass", "lambda_dt", "iterations", "preserve", "solver",
       "precision"},
      {"absolute_time", "freeze_weights", "rebuild_weights", "fix_boundary", "allow_unstable"});
  MeshSmoothingParameters p;
  p.scheme = args.choice("method", {"explicit", "implicit"}, "implicit") == "explicit"
                 ? SmoothingScheme::Explicit
                 : SmoothingScheme::Implicit;
  p.weights = args.choice("weights", {"uniform", "cotan"}, "cotan") == "uniform"
                  ? LaplacianWeights::Uniform
                  : LaplacianWeights::Cotangent;
  p.mass = tools::vertexAreaArgument(args);
  p.iterations = args.integer("iterations", 1);
  if (p.iterations < 1) throw tools::UsageError("-iterations must be at least 1");
  // Default: stiffness frozen at the input, mass updated (see mesh_smoothing.h).
  if (args.has("freeze_weights") && args.has("rebuild_weights"))
    throw tools::UsageError("-freeze_weights and -rebuild_weights exclude each other");
  if (args.has("freeze_weights")) p.weight_update = WeightUpdate::Frozen;
  if (args.has("rebuild_weights")) p.weight_update = WeightUpdate::EveryIteration;
  if (args.has("fix_boundary")) p.boundary = BoundaryCondition::Fixed;
  const std::string preserve = args.choice("preserve", {"none", "volume", "area"}, "none");
  p.shrinkage = preserve == "volume" ? ShrinkageCorrection::PreserveVolume
                : preserve == "area" ? ShrinkageCorrection::PreserveArea
                                     : ShrinkageCorrection::None;
  const tools::SolverChoice solver = tools::solverArgument(args);
  p.implicit_solver = solver.method;
  p.solver = solver.backend;
  if (args.has("absolute_time") && !args.has("lambda_dt"))
    throw tools::UsageError("-absolute_time needs -lambda_dt");
  const double lambda_dt = args.number("lambda_dt", 1.0);
  if (!(lambda_dt > 0.0) || !std::isfinite(lambda_dt))
    throw tools::UsageError("-lambda_dt must be > 0");
  const FieldPrecision precision = tools::precisionArgument(args);

  return tools::forEachInput(
      args, kName, {"ply", "pcd", "las"}, [&](const std::string& input, const std::string& output) {
        tools::ToolInput in(input, kName, tools::InputKind::Mesh);
        const double h = in.spacing();
        if (!(h > 0.0)) throw std::runtime_error("the mesh has no edge of positive length");
        if (p.scheme == SmoothingScheme::Explicit) {
          const double bound =
              explicitStabilityLimit(*in.topology, in.positions, p.weights, p.mass);
          p.time_step = args.has("lambda_dt")
                            ? (args.has("absolute_time") ? lambda_dt : lambda_dt * h * h)
                            : 0.5 * bound;
          std::cerr << kName << ": explicit step " << p.time_step / (h * h)
                    << " h^2; stability bound " << bound / (h * h) << " h^2\n";
          if (p.time_step > bound) {
            if (!args.has("allow_unstable")) {
              throw pcl::BadArgumentException(
                  "the explicit step " + std::to_string(p.time_step / (h * h)) +
                  " h^2 exceeds the stability bound " + std::to_string(bound / (h * h)) +
                  " h^2: the surface would blow up (use -method implicit for large steps, or "
                  "-allow_unstable)");
            }
            tools::warn(kName,
                        "the step exceeds the explicit stability bound: expect the surface to "
                        "blow up");
          }
        } else {
          p.time_step = args.has("absolute_time") ? lambda_dt : lambda_dt * h * h;
        }

        const std::size_t points = static_cast<std::size_t>(in.positions.cols());
        tools::Timer timer("Smoothing");
        tools::ProgressBar progress("> Smoothing");  // redrawn over the Timer's line
        MeshSmoothingReport report;
        const Eigen::Matrix3Xd smoothed = [&] {
          try {
            return smoothMeshPositions(*in.topology, in.positions, p, &report,
                                       [&](int done, int total) { progress.update(done, total); });
          } catch (const SurfaceCollapseException& e) {
            throw std::runtime_error(errorDescription(e) + ": use a smaller -lambda_dt (" +
                                     std::to_string(p.time_step / (h * h)) + " h^2 now)");
          }
        }();
        progress.finish();
        timer.done(points);
        if (p.scheme == SmoothingScheme::Implicit) {
          std::cerr << kName << ": " << report.iterations << " implicit step(s) of "
                    << p.time_step / (h * h) << " h^2, solver ";
          if (report.implicit_solver == ImplicitSolver::ConjugateGradient) {
            std::cerr << "conjugate gradients (" << report.conjugate_gradient_iterations
                      << " iterations)\n";
          } else {
            std::cerr << toString(report.solver) << "\n";
          }
        }
        if (report.fixed_vertices == in.topology->numVertices()) {
          tools::warn(kName,
                      "no vertex is free to move (all on the fixed boundary or without area): "
                      "the output equals the input");
        } else if (report.fixed_vertices > 0) {
          std::cerr << kName << ": " << report.fixed_vertices << " vertices kept in place\n";
        }
        if (report.volume_before != 0.0) {
          std::cerr << kName << ": volume " << report.volume_before << " -> " << report.volume_after
                    << ", area " << report.area_before << " -> " << report.area_after << "\n";
        } else {
          std::cerr << kName << ": area " << report.area_before << " -> " << report.area_after
                    << "\n";
        }
        std::cerr << kName << ": smallest angle " << report.quality_before.min_angle_degrees
                  << " -> " << report.quality_after.min_angle_degrees
                  << " deg, slivers (a corner < " << kSliverAngleDegrees << " deg) "
                  << report.quality_before.slivers << " -> " << report.quality_after.slivers
                  << "\n";
        if (report.quality_after.slivers > report.quality_before.slivers) {
          tools::warn(
              kName,
              std::to_string(report.quality_after.slivers - report.quality_before.slivers) +
                  " slivers created (smaller steps keep the mesh healthier" +
                  (p.weight_update == WeightUpdate::EveryIteration
                       ? "; rebuilt cotangent weights pinch triangles: drop -rebuild_weights)"
                       : ")"));
        }
        const double area_loss = 1.0 - report.area_after / report.area_before;
        if (p.boundary == BoundaryCondition::Free && in.topology->counts().boundary_edges > 0 &&
            area_loss > 0.01) {
          tools::warn(kName, "the free boundary of this open mesh shrank its area by " +
                                 std::to_string(static_cast<int>(100.0 * area_loss + 0.5)) +
                                 "% (-fix_boundary keeps the boundary in place)");
        }

        tools::saveResult(kName, output, in.mesh, smoothed,
                          tools::coordinatePrecision(in.coordinate_precision, precision));
      });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
