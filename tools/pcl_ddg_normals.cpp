// pcl_ddg_normals: per-vertex normals of a mesh, written as nx ny nz vertex properties.
#include "common/mesh_job.h"
#include "common/tool_common.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/surface/mesh_normals.h"

namespace {

constexpr const char* kName = "pcl_ddg_normals";
constexpr const char* kDescription =
    "Estimates per-vertex normals of a mesh and writes them as nx, ny, nz vertex properties.";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk} output.{ply,pcd} [-method uniform|area|angle|mean_curvature]\n"
    "         [-epsilon e (mean_curvature: |M^-1 L x| below e counts as flat; default 0.02/h)]\n"
    "         [-precision float|double]";

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(argc, argv, {"method", "epsilon", "precision"}, {});
  if (args.positional().size() != 2)
    throw tools::UsageError("expected an input and an output file");
  const std::string method =
      args.choice("method", {"uniform", "area", "angle", "mean_curvature"}, "area");
  MeshNormalOptions options;
  options.weighting = method == "uniform"          ? NormalWeighting::Uniform
                      : method == "angle"          ? NormalWeighting::Angle
                      : method == "mean_curvature" ? NormalWeighting::MeanCurvature
                                                   : NormalWeighting::Area;
  if (args.has("epsilon")) {
    if (options.weighting != NormalWeighting::MeanCurvature) {
      throw tools::UsageError("-epsilon applies to -method mean_curvature only");
    }
    options.epsilon = args.number("epsilon", -1.0);
    if (options.epsilon < 0.0) throw tools::UsageError("-epsilon must be >= 0");
  }
  const FieldPrecision precision = tools::precisionArgument(args);
  const std::string output = args.positional()[1];
  if (fileExtension(output) != "ply" && fileExtension(output) != "pcd") {
    throw tools::UsageError("the output must be .ply or .pcd");
  }

  tools::SurfaceMesh in = tools::loadSurfaceMesh(args.positional()[0], kName);
  tools::Timer timer("Computing " + method + " normals");
  const MeshNormals normals = computeMeshNormals(in.topology, in.positions, options);
  timer.done(static_cast<std::size_t>(in.positions.cols()));
  if (normals.invalid_vertices > 0) {
    tools::warn(kName,
                std::to_string(normals.invalid_vertices) + " vertices without a normal (NaN)");
  }
  if (options.weighting == NormalWeighting::MeanCurvature) {
    tools::warn(kName, std::to_string(normals.fallback_vertices) +
                           " flat or boundary vertices took the area-weighted normal");
  }
  const char* names[3] = {"nx", "ny", "nz"};
  for (int d = 0; d < 3; ++d) {
    setVertexField(in.mesh.cloud, names[d], normals.normals.row(d).transpose(), precision);
  }
  tools::saveResult(output, in.mesh);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
