// pcl_ddg_curvature: discrete mean, Gaussian and principal curvatures of a mesh, as vertex
// properties (and optionally as colours).
#include "common/mesh_job.h"
#include "common/tool_common.h"
#include "pcl_ddg/io/color_map.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/operators/curvature.h"

namespace {

constexpr const char* kName = "pcl_ddg_curvature";
constexpr const char* kDescription =
    "Computes discrete curvatures (cotangent Laplacian, angle defect) and writes mean_curvature,\n"
    "gauss_curvature, k1, k2 and vertex_area as vertex properties.";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk} output.{ply,pcd} [-area mixed|voronoi|barycentric]\n"
    "         [-color mean|gauss|k1|k2] [-percentile p (colour scale clamp, default 2)]\n"
    "         [-precision float|double]";

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(argc, argv, {"area", "color", "percentile", "precision"}, {});
  if (args.positional().size() != 2)
    throw tools::UsageError("expected an input and an output file");
  const std::string area = args.choice("area", {"mixed", "voronoi", "barycentric"}, "mixed");
  const MassType mass = area == "voronoi"       ? MassType::Voronoi
                        : area == "barycentric" ? MassType::Barycentric
                                                : MassType::MixedVoronoi;
  const std::string color = args.choice("color", {"none", "mean", "gauss", "k1", "k2"}, "none");
  const double percentile = args.number("percentile", 2.0);
  if (percentile < 0.0 || percentile >= 50.0)
    throw tools::UsageError("-percentile must be in [0, 50)");
  const FieldPrecision precision = tools::precisionArgument(args);
  const std::string output = args.positional()[1];
  if (fileExtension(output) != "ply" && fileExtension(output) != "pcd") {
    throw tools::UsageError("the output must be .ply or .pcd");
  }

  tools::SurfaceMesh in = tools::loadSurfaceMesh(args.positional()[0], kName);
  tools::Timer timer("Computing curvatures");
  const VertexCurvatures c = computeCurvatures(in.topology, in.positions, mass);
  timer.done(static_cast<std::size_t>(in.positions.cols()));
  if (c.invalid_vertices > 0) {
    tools::warn(kName, std::to_string(c.invalid_vertices) + " vertices without area (NaN)");
  }
  if (c.clamped_vertices > 0) {
    tools::warn(kName, std::to_string(c.clamped_vertices) +
                           " vertices with H^2 < K (umbilic or noisy): k1 = k2 = H there");
  }
  const std::pair<const char*, const Eigen::VectorXd*> fields[] = {{"mean_curvature", &c.mean},
                                                                   {"gauss_curvature", &c.gauss},
                                                                   {"k1", &c.kappa1},
                                                                   {"k2", &c.kappa2},
                                                                   {"vertex_area", &c.vertex_area}};
  for (const auto& [name, values] : fields) setVertexField(in.mesh.cloud, name, *values, precision);
  if (color != "none") {
    const Eigen::VectorXd& values = color == "mean"    ? c.mean
                                    : color == "gauss" ? c.gauss
                                    : color == "k1"    ? c.kappa1
                                                       : c.kappa2;
    setVertexColors(in.mesh.cloud,
                    colorize(values, ColorMap::Diverging, {percentile, 100.0 - percentile}));
  }
  tools::saveResult(output, in.mesh);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
