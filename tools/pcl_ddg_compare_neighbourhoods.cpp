// pcl_ddg_compare_neighbourhoods: one estimator, run with topological (mesh rings, or an organized
// cloud's pixel grid) and Euclidean (kd-tree) neighbourhoods; how much the normals and the
// neighbour sets differ, per point.
#include <cstdio>

#include "common/fit_steps.h"
#include "common/tool_common.h"
#include "common/tool_output.h"
#include "pcl_ddg/features/neighbourhood_comparison.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/render/color_map.h"

namespace {

constexpr const char* kName = "pcl_ddg_compare_neighbourhoods";
constexpr const char* kDescription =
    "Runs a normal estimator on a mesh with mesh-ring (BFS), or on an organized cloud with "
    "pixel-grid,\n"
    "and with kd-tree neighbourhoods, prints\n"
    "how far the normals differ and how much the neighbour sets overlap, and writes per-vertex\n"
    "angle_difference (degrees) and overlap (Jaccard, 0..1), coloured by the angle difference\n"
    "(by default unless the input has colours of its own; -color none keeps them as they are).";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk,pcd,las} output.{ply,pcd,las} [-method pca|quadric] [-k N "
    "(default 16)]\n"
    "         [-radius r or 2.5h (instead of -k)] [-max_nn N (with -radius; default 64)]\n"
    "         [-max_depth_jump f (organized clouds; default 0.02)]\n"
    "         [-viewpoint x,y,z] [-color angle_difference|overlap|none] [-precision float|double]";

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(
      argc, argv,
      {"method", "k", "radius", "max_nn", "viewpoint", "precision", "color", "max_depth_jump"}, {});
  const std::string method = args.choice("method", {"pca", "quadric"}, "pca");
  args.choice("color", {"angle_difference", "overlap", "none"}, "none");
  const FieldPrecision precision = tools::precisionArgument(args);
  tools::checkLocalFitArguments(args);
  return tools::forEachInput(
      args, kName, {"ply", "pcd", "las", "laz"},
      [&](const std::string& input, const std::string& output) {
        tools::ToolInput in(input, kName);
        const bool organized = !in.topology && in.points()->height > 1;
        if (!in.topology && !organized)
          throw std::runtime_error(input +
                                   " has no faces and no pixel grid: no topological "
                                   "neighbourhoods to compare");
        LocalFitOptions options = tools::localFitArguments(
            args, in, method == "pca" ? LocalFitMethod::PCA : LocalFitMethod::Quadric);
        if (!args.has("k")) options.k = 16;

        tools::Timer timer("Comparing " + method + " normals from " +
                           (organized ? "the pixel grid" : "mesh rings") + " and from a kd-tree");
        const NeighbourhoodComparison c = [&] {
          const tools::QuietPCLWarnings quiet;
          return compareNeighbourhoods(in.local(), in.topology, options);
        }();
        timer.done(in.points()->size());
        in.releaseLocal();
        tools::warnAboutLocalFit(kName, c.topological);
        tools::warnAboutLocalFit(kName, c.kd_tree);
        const NeighbourhoodComparison::Summary& s = c.summary;
        std::printf(
            "angle difference (degrees) over %lld vertices: mean %.3f, median %.3f, 95th "
            "percentile "
            "%.3f, max %.3f\n",
            static_cast<long long>(s.compared), s.mean, s.median, s.percentile95, s.max);
        std::printf("vertices over 5 degrees: %.2f%%, over 30 degrees: %.2f%%\n",
                    100.0 * s.share_over_5, 100.0 * s.share_over_30);
        std::printf("neighbourhood overlap (mean Jaccard): %.3f\n", s.mean_overlap);

        setVertexField(in.mesh.cloud, "angle_difference", c.angle_difference, precision);
        setVertexField(in.mesh.cloud, "overlap", c.overlap, precision);
        // An input's own colours are kept unless -color asks for a map.
        const std::string color =
            args.text("color", vertexColorLayout(in.mesh.cloud) ? "none" : "angle_difference");
        if (color == "angle_difference") {
          // From the smallest difference to 30 degrees (larger ones saturate).
          const Eigen::VectorXd clamped = c.angle_difference.cwiseMin(30.0);
          tools::setColorMapFields(kName, in.mesh.cloud, output, color, c.angle_difference,
                                   colorize(clamped, ColorMap::Sequential, {0.0, 100.0}));
        } else if (color == "overlap") {
          tools::setColorMapFields(kName, in.mesh.cloud, output, color, c.overlap,
                                   colorize(c.overlap, ColorMap::Sequential, {0.0, 100.0}));
        }
        tools::saveResult(kName, output, in, precision);
      });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
