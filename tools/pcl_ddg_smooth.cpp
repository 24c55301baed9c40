// pcl_ddg_smooth: Laplacian smoothing of a mesh's vertex positions, explicit (many small steps),
// implicit (few large ones) or Taubin's lambda|mu (without shrinking); see kDescription.
#include <pcl/exceptions.h>

#include <cmath>
#include <iostream>
#include <sstream>

#include "common/operator_options.h"
#include "common/tool_common.h"
#include "common/tool_input.h"
#include "common/tool_output.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/surface/mesh_smoothing.h"
#include "pcl_ddg/surface/smoothing_steps.h"

namespace {

constexpr const char* kName = "pcl_ddg_smooth";
constexpr const char* kDescription =
    "Smooths a mesh by Laplacian flow dx/dt = A^-1 L x: explicit (forward Euler; stable only for\n"
    "small steps, the bound is printed), implicit (backward Euler, one sparse Cholesky or\n"
    "conjugate-gradient solve per iteration, by default whichever costs less; any step) or Taubin\n"
    "(a step of -lambda then one of -mu per iteration: smooths without shrinking).\n"
    "A averages L: the vertex areas (-average area: the geometric flow, whose time step\n"
    "-lambda_dt is in units of h^2, h = mean edge length, so one command line works on any scan;\n"
    "-absolute_time takes it in length^2) or the vertex degrees (-average degree: each vertex\n"
    "moves towards the mean of its neighbours; steps are dimensionless, explicit ones stable up\n"
    "to 1). -weights umbrella is uniform weights averaged by degree, the default of -method\n"
    "explicit and taubin; implicit defaults to cotan weights averaged by area.\n"
    "Default weight update: none, the Laplacian and the areas stay those of the input (of three\n"
    "policies it kept coarse scans with thin parts healthiest before the thickness limit below,\n"
    "and it factorises once);\n"
    "-update_mass lets the areas follow the surface (conformalized mean-curvature flow),\n"
    "-rebuild_weights rebuilds both every iteration (mean-curvature flow: thin parts pinch into\n"
    "slivers). -freeze_weights, the default, is accepted for old command lines.\n"
    "Thin parts (handles, legs, horns a few edges thick) would collapse into slivers under large\n"
    "steps: by default a vertex whose inner ball (the largest empty ball touching it from inside,\n"
    "half the local thickness) has radius r smooths for about -thickness_limit c (default 0.5)\n"
    "times r^2 at most, the rest of the surface for the whole time; -thickness_limit 0 smooths\n"
    "everything for the whole time. Area-averaged explicit and implicit steps only.";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk} output.{ply,pcd,las}\n"
    "         [-method explicit|implicit|taubin (default implicit)]\n"
    "         [-weights uniform|cotan|umbrella (default: cotan implicit, umbrella otherwise)]\n"
    "         [-average area|degree] [-area mixed|voronoi|barycentric]\n"
    "         [-lambda_dt t (default: implicit 1, explicit half the stability bound)]\n"
    "         [-lambda l (taubin, default 0.5)] [-mu m (taubin, default -0.53)]\n"
    "         [-iterations n (default 1)] [-absolute_time]\n"
    "         [-update_mass | -rebuild_weights | -freeze_weights (default)]\n"
    "         [-thickness_limit c (default 0.5; 0: none)]\n"
    "         [-fix_boundary] [-allow_unstable]\n"
    "         [-preserve volume|area] [-solver auto|cholmod|ldlt|cg] [-precision float|double]";

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(
      argc, argv,
      {"method", "weights", "average", "area", "mass", "lambda_dt", "lambda", "mu", "iterations",
       "preserve", "solver", "precision", "thickness_limit"},
      {"absolute_time", "freeze_weights", "update_mass", "rebuild_weights", "fix_boundary",
       "allow_unstable"});
  MeshSmoothingParameters p;
  const std::string method = args.choice("method", {"explicit", "implicit", "taubin"}, "implicit");
  p.scheme = method == "explicit" ? SmoothingScheme::Explicit
             : method == "taubin" ? SmoothingScheme::Taubin
                                  : SmoothingScheme::Implicit;
  // Defaults (smoothing_steps.h): cotan by area for implicit and with -area, else umbrella.
  const bool areas_asked = args.has("area") || args.has("mass");
  try {
    chooseOperator(
        p, args.has("weights") ? args.choice("weights", {"uniform", "cotan", "umbrella"}, "") : "",
        args.has("average") ? args.choice("average", {"area", "degree"}, "") : "", areas_asked);
  } catch (const pcl::BadArgumentException& e) {
    throw tools::UsageError(errorDescription(e));
  }
  p.mass = tools::vertexAreaArgument(args);
  p.iterations = args.integer("iterations", 1);
  if (p.iterations < 1) throw tools::UsageError("-iterations must be at least 1");
  if (args.has("freeze_weights") + args.has("update_mass") + args.has("rebuild_weights") > 1)
    throw tools::UsageError(
        "-freeze_weights, -update_mass and -rebuild_weights exclude each other");
  if (args.has("update_mass")) p.weight_update = WeightUpdate::FrozenStiffness;
  if (args.has("rebuild_weights")) p.weight_update = WeightUpdate::EveryIteration;
  try {
    chooseThicknessLimit(p,
                         args.has("thickness_limit")
                             ? std::optional<double>(args.number("thickness_limit", 0.0))
                             : std::nullopt,
                         "-thickness_limit");
  } catch (const pcl::BadArgumentException& e) {
    throw tools::UsageError(errorDescription(e));
  }
  if (args.has("fix_boundary")) p.boundary = BoundaryCondition::Fixed;
  const std::string preserve = args.choice("preserve", {"none", "volume", "area"}, "none");
  p.shrinkage = preserve == "volume" ? ShrinkageCorrection::PreserveVolume
                : preserve == "area" ? ShrinkageCorrection::PreserveArea
                                     : ShrinkageCorrection::None;
  const SolverChoice solver = tools::solverArgument(args);
  p.implicit_solver = solver.method;
  p.solver = solver.backend;
  const bool taubin = p.scheme == SmoothingScheme::Taubin;
  if (taubin && args.has("lambda_dt"))
    throw tools::UsageError("-method taubin takes -lambda and -mu, not -lambda_dt");
  if (!taubin && (args.has("lambda") || args.has("mu")))
    throw tools::UsageError("-lambda and -mu are -method taubin's (the flow takes -lambda_dt)");
  const char* step_option = taubin ? "lambda" : "lambda_dt";
  if (args.has("absolute_time") && !args.has(step_option))
    throw tools::UsageError(std::string("-absolute_time needs -") + step_option);
  if (args.has("absolute_time") && p.average == FlowAverage::Degree)
    throw tools::UsageError("-absolute_time is for -average area (degree steps have no unit)");
  RelativeSteps steps;
  if (args.has(step_option)) steps.step = args.number(step_option, 0.0);
  steps.mu = args.number("mu", steps.mu);
  if (steps.step && (!(*steps.step > 0.0) || !std::isfinite(*steps.step)))
    throw tools::UsageError(std::string("-") + step_option + " must be > 0");
  if (taubin && (!(steps.mu < -steps.step.value_or(0.5)) || !std::isfinite(steps.mu)))
    throw tools::UsageError("-mu must be below -lambda (e.g. -lambda 0.5 -mu -0.53)");
  steps.absolute_time = args.has("absolute_time");
  steps.allow_unstable = args.has("allow_unstable");
  steps.remedy = "-method implicit for large steps, -weights umbrella, or -allow_unstable";
  const FieldPrecision precision = tools::precisionArgument(args);

  return tools::forEachInput(
      args, kName, {"ply", "pcd", "las", "laz"},
      [&](const std::string& input, const std::string& output) {
        tools::ToolInput in(input, kName, tools::InputKind::Mesh);
        const ResolvedSteps resolved = resolveSteps(*in.topology, in.positions(), steps, p);
        std::cerr << kName << ": " << describeSteps(p, resolved) << "\n";
        if (resolved.unstable) {
          tools::warn(kName, "the steps exceed the stability bound: expect the surface to blow up");
        }

        const std::size_t points = static_cast<std::size_t>(in.positions().cols());
        tools::Timer timer("Smoothing");
        tools::ProgressBar progress("> Smoothing");  // redrawn over the Timer's line
        MeshSmoothingReport report;
        const Eigen::Matrix3Xd smoothed = [&] {
          try {
            return smoothMeshPositions(*in.topology, in.positions(), p, &report,
                                       [&](int done, int total) { progress.update(done, total); });
          } catch (const SurfaceCollapseException& e) {
            std::ostringstream what;
            what << errorDescription(e) << ": use a smaller -" << step_option << " ("
                 << p.time_step / resolved.unit << resolved.unit_name << " now)";
            throw std::runtime_error(what.str());
          }
        }();
        progress.finish();
        timer.done(points);
        if (p.scheme == SmoothingScheme::Implicit) {
          std::cerr << kName << ": " << report.iterations << " implicit step(s) of "
                    << p.time_step / resolved.unit << resolved.unit_name << ", solver ";
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
        if (report.thin_vertices > 0) {
          // Thinner than this, a part would be smoothed for more than the limit allows.
          const double reach = std::sqrt(p.time_step * p.iterations / p.thickness_limit);
          std::cerr << kName << ": -thickness_limit " << p.thickness_limit << ": "
                    << report.thin_vertices << " of " << points
                    << " vertices smoothed for < 90% of the time (inner radius < "
                    << reach / meanEdgeLength(*in.topology, in.positions())
                    << " h, or next to such parts); mean time fraction "
                    << report.mean_time_fraction << "\n";
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
                          tools::coordinatePrecision(in.coordinate_precision, precision), {},
                          nullptr, in.outputFaces());
      });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
