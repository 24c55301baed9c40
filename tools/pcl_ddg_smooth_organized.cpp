// pcl_ddg_smooth_organized: heat-equation smoothing of an organized cloud (a depth image) on its
// pixel grid, moving every point along its viewing ray; holes and depth jumps are respected.
#include <pcl/exceptions.h>

#include <cmath>
#include <iostream>

#include <string>

#include "common/operator_options.h"
#include "common/tool_common.h"
#include "common/tool_output.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/surface/grid_smoothing.h"

namespace {

constexpr const char* kName = "pcl_ddg_smooth_organized";
constexpr const char* kDescription =
    "Smooths an organized cloud (width x height: a Kinect frame, a PLY range_grid scan) by the\n"
    "heat equation on its pixel grid (5-point stencil), applied to each point's range along its\n"
    "ray from the sensor origin (the PCD VIEWPOINT), so points stay on their rays. NaN pixels are\n"
    "holes: never filled, never spread. Neighbours whose ranges differ by more than\n"
    "-max_depth_jump (relative) are not coupled, so object edges stay sharp (-max_jump, its "
    "former\n"
    "name, is still read). -lambda_dt is in pixel^2; explicit steps need it below 0.25.";
constexpr const char* kSyntax =
    "input.{pcd,ply} output.{pcd,ply} [-method explicit|implicit (default implicit)]\n"
    "         [-lambda_dt t (default: implicit 1, explicit 0.2)] [-iterations n (default 1)]\n"
    "         [-max_depth_jump f (default 0.05)] [-solver auto|cholmod|ldlt|cg] [-allow_unstable]";

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(
      argc, argv, {"method", "lambda_dt", "iterations", "max_depth_jump", "max_jump", "solver"},
      {"allow_unstable"});
  GridSmoothingParameters p;
  p.scheme = args.choice("method", {"explicit", "implicit"}, "implicit") == "explicit"
                 ? SmoothingScheme::Explicit
                 : SmoothingScheme::Implicit;
  p.time_step = args.number("lambda_dt", p.scheme == SmoothingScheme::Explicit ? 0.2 : 1.0);
  p.iterations = args.integer("iterations", 1);
  // One name with pcl_ddg_normals' -max_depth_jump; the old -max_jump still works.
  if (args.has("max_jump") && args.has("max_depth_jump"))
    throw tools::UsageError("-max_jump is the old name of -max_depth_jump: give one");
  const char* jump = args.has("max_jump") ? "max_jump" : "max_depth_jump";
  p.max_depth_jump = args.number(jump, 0.05);
  if (!(p.time_step > 0.0)) throw tools::UsageError("-lambda_dt must be > 0");
  if (p.iterations < 1) throw tools::UsageError("-iterations must be at least 1");
  if (!(p.max_depth_jump > 0.0)) throw tools::UsageError(std::string("-") + jump + " must be > 0");
  const SolverChoice solver = tools::solverArgument(args);
  p.implicit_solver = solver.method;
  p.solver = solver.backend;
  if (p.scheme == SmoothingScheme::Explicit && p.time_step >= 0.25) {
    if (!args.has("allow_unstable")) {
      throw pcl::BadArgumentException(
          "explicit steps of 0.25 pixel^2 or more are unstable (use -method implicit for large "
          "steps, or -allow_unstable)");
    }
    tools::warn(kName, "explicit steps of 0.25 pixel^2 or more are unstable: expect noise to grow");
  }

  return tools::forEachInput(
      args, kName, {"pcd", "ply"}, [&](const std::string& input, const std::string& output) {
        tools::Timer load_timer("Loading " + input);
        MeshFile file = readMeshFile(input);
        pcl::PolygonMesh& cloud = file.mesh;
        const SensorPose& sensor = file.sensor_pose;
        const std::size_t points = static_cast<std::size_t>(cloud.cloud.width) * cloud.cloud.height;
        load_timer.done(points);
        if (cloud.cloud.height < 2) {
          throw std::runtime_error(input + " is not organized (height " +
                                   std::to_string(cloud.cloud.height) + ")");
        }

        const Eigen::Matrix3Xd& positions = file.positions;
        tools::Timer timer("Smoothing");
        GridSmoothingReport report;
        const Eigen::Matrix3Xd smoothed = smoothOrganizedPositions(
            positions, static_cast<int>(cloud.cloud.width), static_cast<int>(cloud.cloud.height),
            sensor.origin, p, &report);
        timer.done(points);
        std::cerr << kName << ": " << report.valid_pixels << " pixels, " << report.holes
                  << " holes, " << report.cut_pairs << " neighbour pairs cut at depth jumps\n";
        if (report.valid_pixels == 0)
          tools::warn(kName, "no valid pixel to smooth: the output equals the input");
        if (report.points_at_origin > 0) {
          tools::warn(kName,
                      std::to_string(report.points_at_origin) +
                          " points at the sensor origin kept in place (no ray to move along)");
        }
        tools::saveResult(
            kName, output, cloud, smoothed,
            tools::coordinatePrecision(file.coordinate_precision, FieldPrecision::Float), sensor);
      });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
