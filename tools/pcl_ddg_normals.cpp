// pcl_ddg_normals: per-vertex normals of a mesh (face-weighted or mean-curvature), or of a mesh or
// point cloud by a plane (pca) or quadric fit to each point's neighbours.
#include "common/fit_steps.h"
#include "common/tool_common.h"
#include "common/tool_output.h"
#include "pcl_ddg/features/consistent_orientation.h"
#include "pcl_ddg/features/fit_choices.h"
#include "pcl_ddg/features/ring_surface_variation.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/render/mesh_render.h"
#include "pcl_ddg/result_warnings.h"
#include "pcl_ddg/surface/mesh_normals.h"
#include "pcl_ddg/tiling/out_of_core_fit.h"

namespace {

constexpr const char* kName = "pcl_ddg_normals";
constexpr const char* kDescription =
    "Estimates normals of a mesh or a point cloud: from the mesh faces (uniform, area, angle,\n"
    "mean_curvature) or by fitting a plane (pca), a quadric, or a robust plane (robust: its own\n"
    "scale up to k, not across sharp edges; writes also scale and confidence) to each point's\n"
    "neighbours, found on\n"
    "the mesh (rings), on an organized cloud's pixel grid (grid: never across a depth jump;\n"
    "pca there fits the smallest square window of k pixels from its running window sums) or in "
    "space\n"
    "(kdtree). An organized cloud stays organized. Writes nx ny nz (.ply) or normal_x "
    "normal_y\n"
    "normal_z curvature (.pcd; for mesh methods the curvature is PCL's surface variation over\n"
    "the vertex's 1-ring).";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk,pcd,las} output.{ply,pcd,las}\n"
    "         [-method uniform|area|angle|mean_curvature|pca|quadric|robust (default: area on "
    "meshes,\n"
    "                  pca on clouds)]\n"
    "         [-epsilon e (mean_curvature: |M^-1 L x| below e counts as flat; default 0.02/h)]\n"
    "         [-neighbours rings|grid|kdtree (pca, quadric, robust; default rings on meshes, grid "
    "on "
    "organized "
    "clouds)]\n"
    "         [-k N (default 16, quadric 20, robust 96 or all points: the "
    "neighbourhood searched)]\n"
    "         [-max_depth_jump f (grid: a range change above f times the range per pixel cuts the "
    "grid;\n"
    "                  default 0.02)]\n"
    "         [-radius r (a length, or a multiple of the mean spacing like 2.5h; instead of -k)]\n"
    "         [-max_nn N (with -radius: at most the N nearest; default 64)]\n"
    "         [-min_nn N (with -radius: the N nearest where the ball holds fewer)]\n"
    "         [-viewpoint x,y,z (clouds: orient normals towards it; default the PCD's VIEWPOINT)]\n"
    "         [-orient viewpoint|up|mst|mesh (fits: towards the viewpoint (clouds' "
    "default),\n"
    "                  up (aerial and terrestrial LiDAR: n . up >= 0; LAS files' default without\n"
    "                  -viewpoint), along a minimum spanning\n"
    "                  tree of the 10 nearest on the mesh, the pixel grid or in space (merged\n"
    "                  scans; -viewpoint, an organized frame's sensor or -up decides every sign\n"
    "                  it can and the tree the rest; else each tree's highest point faces up),\n"
    "                  or like the faces (meshes' default))]\n"
    "         [-up x,y,z (-orient up and mst: the up direction; default 0,0,1)]\n"
    "         [-classes 2,6 (clouds with a classification, like LAS: fit only these classes;\n"
    "                  every point is written, NaN elsewhere)]\n"
    "         [-normal_map out.png (organized clouds: the normals as an image, (n + 1) / 2 as "
    "RGB)]\n"
    "         [-precision float|double]\n"
    "         [-memory SIZE (clouds larger than memory: fitted tile by tile within SIZE, like 2G;\n"
    "                  input binary PCD or PLY, LAS or LAZ; the same values as in memory)]";

/** Says how many normals the spanning tree turned. */
void reportSpanningTree(const pcl_ddg::ConsistentOrientationReport& report) {
  char share[32];
  std::snprintf(share, sizeof share, "%.1f %%", 100.0 * report.flippedShare());
  std::cerr << kName << ": the spanning tree turned " << report.flipped_points << " of "
            << report.oriented_points << " normals (" << share << ") in " << report.components
            << " components";
  if (report.confident_points > 0 || report.ambiguous_regions > 0) {
    std::cerr << "; " << report.confident_points << " signed by the reference, "
              << report.propagated_flips << " of the others turned by propagation in "
              << report.ambiguous_regions << " regions";
  }
  std::cerr << "\n";
}

// Points fitted at a time (fitLocalSurfacesInSlices): 8 MB of pcl::Normal.
constexpr std::size_t kSlicePoints = std::size_t{1} << 18;

/** An organized cloud's normals as an image: (n + 1) / 2 as red, green, blue; black where none. */
void saveNormalMap(const std::string& path, const pcl::PointCloud<pcl::Normal>& normals) {
  if (normals.height < 2) {
    throw pcl_ddg::tools::UsageError("-normal_map needs an organized cloud (width x height)");
  }
  pcl_ddg::Image image;
  image.width = static_cast<int>(normals.width);
  image.height = static_cast<int>(normals.height);
  image.rgb.assign(normals.size() * 3, 0);
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const Eigen::Vector3f n = normals[i].getNormalVector3fMap();
    if (!n.allFinite()) continue;
    for (int c = 0; c < 3; ++c)
      image.rgb[3 * i + c] = static_cast<std::uint8_t>(std::lround(127.5f * (n[c] + 1.0f)));
  }
  pcl_ddg::tools::Timer timer("Saving " + path);
  pcl_ddg::savePNG(path, image);
  timer.done(normals.size());
}

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(
      argc, argv,
      {"method", "epsilon", "neighbours", "k", "radius", "max_nn", "viewpoint", "precision",
       "memory", "max_depth_jump", "orient", "normal_map", "up", "min_nn", "classes"},
      {});
  const FieldPrecision precision = tools::precisionArgument(args);
  const std::vector<std::string> methods = {"uniform", "area",    "angle", "mean_curvature",
                                            "pca",     "quadric", "robust"};
  const std::string requested = args.has("method") ? args.choice("method", methods, "area") : "";
  const bool fitted = requested == "pca" || requested == "quadric" || requested == "robust";
  const bool neighbour_options = args.has("neighbours") || args.has("k") || args.has("radius") ||
                                 args.has("max_depth_jump") || args.has("orient") ||
                                 args.has("up") || args.has("min_nn") || args.has("classes");
  if (!requested.empty() && !fitted && neighbour_options) {
    throw tools::UsageError(
        "-neighbours, -k, -radius, -min_nn, -max_depth_jump, -orient, -up and -classes apply to "
        "pca, quadric and robust");
  }
  if (args.has("epsilon") && requested != "mean_curvature") {
    throw tools::UsageError("-epsilon applies to -method mean_curvature only");
  }
  if (args.has("epsilon") && !(args.number("epsilon", 0.0) >= 0.0))
    throw tools::UsageError("-epsilon must be >= 0");
  tools::checkLocalFitArguments(args);
  const std::optional<NormalOrientation> orientation = tools::orientationArgument(args);
  const bool spanning_tree = orientation == NormalOrientation::SpanningTree;
  if (args.has("memory")) {
    // A cloud larger than memory: fitted tile by tile from the file (pcl_ddg/tiling).
    if (!requested.empty() && !fitted)
      throw tools::UsageError("-memory applies to pca, quadric and robust on clouds");
    if (orientation && orientation != NormalOrientation::Viewpoint &&
        orientation != NormalOrientation::Up)
      throw tools::UsageError("-orient " + *args.value("orient") +
                              " needs the whole cloud; with -memory normals face the viewpoint "
                              "or up");
    LocalFitOptions options =
        tools::outOfCoreFitArguments(args, requested == "quadric"  ? LocalFitMethod::Quadric
                                           : requested == "robust" ? LocalFitMethod::Robust
                                                                   : LocalFitMethod::PCA);
    if (orientation == NormalOrientation::Up) options.orientation = NormalOrientation::Up;
    return tools::fitEachInputOutOfCore(
        kName, args, options, precision,
        [&](pcl::PCLPointCloud2& piece, const std::string& output, const LocalFitResult& fit) {
          tools::FitFieldWriter(piece, output, precision, requested == "robust").write(0, fit);
        });
  }
  return tools::forEachInput(
      args, kName, {"ply", "pcd", "las", "laz"},
      [&](const std::string& input, const std::string& output) {
        if (args.has("normal_map")) tools::checkOutputFile(*args.value("normal_map"), {input});
        tools::ToolInput in(input, kName);
        if (orientation) {
          tools::usage(
              [&] { checkOrientationInput(*orientation, in.topology != nullptr, kToolStyle); });
        }
        const std::string method =
            !requested.empty() ? requested : (in.topology && !neighbour_options ? "area" : "pca");
        if (method != "pca" && method != "quadric" && method != "robust") {
          if (!in.topology)
            throw tools::UsageError("-method " + method +
                                    " needs a mesh; this input is a point cloud");
          MeshNormalOptions options;
          options.weighting = chooseNormalWeighting(method, "method", kToolStyle);
          if (args.has("epsilon")) {
            options.epsilon = args.number("epsilon", -1.0);
            if (options.epsilon < 0.0) throw tools::UsageError("-epsilon must be >= 0");
          }
          const Eigen::Matrix3Xd& positions = in.positions();
          tools::Timer timer("Computing " + method + " normals");
          const MeshNormals normals = computeMeshNormals(*in.topology, positions, options);
          timer.done(static_cast<std::size_t>(positions.cols()));
          for (const std::string& message : meshNormalWarnings(normals, options.weighting))
            tools::warn(kName, message);
          tools::setNormalTriple(in.mesh.cloud, output, normals.normals, precision);
          if (fileExtension(output) == "pcd") {
            // What pcl::PointNormal expects beside the normal: PCL's surface variation, over the
            // 1-ring.
            setVertexField(in.mesh.cloud, "curvature",
                           ringSurfaceVariation(*in.topology, positions), precision);
          }
        } else {
          LocalFitOptions options =
              tools::localFitArguments(args, in, chooseFitMethod(method, kToolStyle));
          options.orientation = orientation.value_or(NormalOrientation::MeshFaces);
          tools::orientLasUp(kName, args, in.las && !in.topology, options);
          // An organized frame has one sensor: it decides the tree's signs (unless -up does).
          options.seed_facing_viewpoint =
              !args.has("up") && (args.has("viewpoint") || in.points()->height > 1);
          const std::int64_t left_out = tools::keepOnlyClasses(kName, args, in);
          const tools::SamplingCheck sampling = tools::checkSampling(kName, in, options);
          tools::Timer timer("Computing " + method + " normals (" +
                             tools::describeNeighbourhood(options) +
                             (spanning_tree ? ", oriented along a spanning tree)" : ")"));
          // Written into the output a slice at a time, never the whole pcl::Normal cloud beside it.
          tools::FitFieldWriter fields(in.mesh.cloud, output, precision, method == "robust");
          in.lendRows();  // a float cloud's x, y, z are in the fit's floats until releaseLocal()
          pcl::PointCloud<pcl::Normal> map_normals;  // -normal_map: all of them (one slice)
          LocalFitResult result = [&] {
            const tools::QuietPCLWarnings quiet;
            return fitLocalSurfacesInSlices(in.local(), in.topology, options,
                                            args.has("normal_map") ? 0 : kSlicePoints,
                                            [&](std::size_t first, LocalFitResult& slice) {
                                              fields.write(first, slice);
                                              if (args.has("normal_map"))
                                                map_normals = std::move(slice.normals);
                                            });
          }();
          timer.done(in.points()->size());
          in.releaseLocal();
          result.failed_points -= left_out;  // -classes: not fitted by request
          tools::warnAboutLocalFit(kName, result);
          tools::warnAboutRadius(kName, sampling, options, result);
          if (spanning_tree) reportSpanningTree(result.orientation);
          if (args.has("normal_map")) saveNormalMap(*args.value("normal_map"), map_normals);
        }
        tools::saveResult(kName, output, in, precision);
      });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
