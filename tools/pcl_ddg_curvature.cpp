// pcl_ddg_curvature: curvatures of a mesh (discrete: cotangent Laplacian and angle defect) or of a
// mesh or point cloud (fitted: a quadric through each point's neighbours), as vertex properties
// and optionally as colours.
#include <cstdio>

#include "common/fit_steps.h"
#include "common/operator_options.h"
#include "common/tool_common.h"
#include "common/tool_output.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/render/color_map.h"
#include "pcl_ddg/result_warnings.h"
#include "pcl_ddg/surface/scalar_field_smoothing.h"

namespace {

constexpr const char* kName = "pcl_ddg_curvature";
constexpr const char* kDescription =
    "Computes curvatures and writes mean_curvature (signed, > 0 where convex), gauss_curvature, k1 "
    ">= k2\n"
    "as vertex properties: -method cotan (mesh; cotangent Laplacian and angle defect, also "
    "vertex_area)\n"
    "or quadric (mesh or cloud; quadric fitted to each point's neighbours, also the k1 direction\n"
    "k1_direction_x/y/z and the normal). -smooth t first smooths the four curvature fields by the\n"
    "implicit heat flow on the mesh for a time t in units of h^2 (h = mean edge length).";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk,pcd,las} output.{ply,pcd,las} [-method cotan|quadric (default: "
    "cotan on "
    "meshes)]\n"
    "         [-area mixed|voronoi|barycentric (cotan)]\n"
    "         [-neighbours rings|kdtree] [-k N (default 20)] [-radius r or 2.5h] [-max_nn N]\n"
    "         [-viewpoint x,y,z] [-classes 2,6 (fit only these classes, NaN elsewhere)] "
    "(quadric)\n"
    "         [-smooth t (heat flow time in h^2, meshes)]\n"
    "         [-color mean|gauss|k1|k2] [-percentile p (colour scale clamp, default 2)]\n"
    "         [-precision float|double]\n"
    "         [-memory SIZE (clouds larger than memory, quadric: fitted tile by tile within SIZE\n"
    "                  like 2G; input binary PCD or PLY, LAS or LAZ; no -smooth, no -color)]";

// The four curvature fields, as written.
struct CurvatureFields {
  Eigen::VectorXd mean, gauss, k1, k2;
};

// Sets the quadric's k1 direction and normal fields; returns its curvatures (H and K from k1, k2).
CurvatureFields quadricFields(pcl::PCLPointCloud2& cloud, const std::string& output,
                              const pcl_ddg::LocalFitResult& result,
                              pcl_ddg::FieldPrecision precision) {
  const auto n = static_cast<Eigen::Index>(result.curvatures.size());
  CurvatureFields c{{}, {}, Eigen::VectorXd(n), Eigen::VectorXd(n)};
  Eigen::Matrix3Xd direction(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const pcl::PrincipalCurvatures& p = result.curvatures[i];
    c.k1[i] = p.pc1;
    c.k2[i] = p.pc2;
    direction.col(i) << p.principal_curvature_x, p.principal_curvature_y, p.principal_curvature_z;
  }
  c.mean = 0.5 * (c.k1 + c.k2);
  c.gauss = c.k1.cwiseProduct(c.k2);
  const char* names[] = {"k1_direction_x", "k1_direction_y", "k1_direction_z"};
  for (int d = 0; d < 3; ++d)
    pcl_ddg::setVertexField(cloud, names[d], direction.row(d).transpose(), precision);
  pcl_ddg::tools::setNormalFields(cloud, output, result.normals, precision);
  return c;
}

void setCurvatureFields(pcl::PCLPointCloud2& cloud, const CurvatureFields& c,
                        pcl_ddg::FieldPrecision precision) {
  const std::pair<const char*, const Eigen::VectorXd*> fields[] = {
      {"mean_curvature", &c.mean}, {"gauss_curvature", &c.gauss}, {"k1", &c.k1}, {"k2", &c.k2}};
  for (const auto& [name, values] : fields)
    pcl_ddg::setVertexField(cloud, name, *values, precision);
}

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(
      argc, argv,
      {"method", "area", "neighbours", "k", "radius", "max_nn", "smooth", "color", "percentile",
       "precision", "memory", "classes"},
      {});
  const std::string color = args.choice("color", {"none", "mean", "gauss", "k1", "k2"}, "none");
  const double percentile = args.number("percentile", 2.0);
  if (percentile < 0.0 || percentile >= 50.0)
    throw tools::UsageError("-percentile must be in [0, 50)");
  const FieldPrecision precision = tools::precisionArgument(args);
  const std::string requested =
      args.has("method") ? args.choice("method", {"cotan", "quadric"}, "cotan") : "";
  if (requested == "quadric" && args.has("area"))
    throw tools::UsageError("-area applies to -method cotan");
  if (requested == "cotan" &&
      (args.has("neighbours") || args.has("k") || args.has("radius") || args.has("classes"))) {
    throw tools::UsageError("-neighbours, -k, -radius and -classes apply to -method quadric");
  }
  const MassType mass = tools::vertexAreaArgument(args);  // validated before loading
  tools::checkLocalFitArguments(args);
  const double smooth_time = args.number("smooth", 1.0);
  if (!(smooth_time > 0.0)) throw tools::UsageError("-smooth must be > 0");
  if (args.has("memory")) {
    // A cloud larger than memory: quadrics fitted tile by tile from the file (pcl_ddg/tiling).
    if (requested == "cotan") throw tools::UsageError("-memory applies to -method quadric");
    if (args.has("smooth") || color != "none") {
      throw tools::UsageError("-smooth and -color need the whole field at once; not with -memory");
    }
    const LocalFitOptions options = tools::outOfCoreFitArguments(args, LocalFitMethod::Quadric);
    return tools::fitEachInputOutOfCore(
        kName, args, options, precision,
        [&](pcl::PCLPointCloud2& piece, const std::string& output, const LocalFitResult& fit) {
          setCurvatureFields(piece, quadricFields(piece, output, fit, precision), precision);
        });
  }

  return tools::forEachInput(
      args, kName, {"ply", "pcd", "las", "laz"},
      [&](const std::string& input, const std::string& output) {
        tools::ToolInput in(input, kName);
        const std::string method =
            !requested.empty() ? requested : (in.topology ? "cotan" : "quadric");
        CurvatureFields curvatures;
        if (method == "cotan") {
          if (!in.topology)
            throw tools::UsageError("-method cotan needs a mesh; this input is a point cloud");
          tools::Timer timer("Computing curvatures");
          const VertexCurvatures c = computeCurvatures(*in.topology, in.positions(), mass);
          timer.done(static_cast<std::size_t>(in.positions().cols()));
          for (const std::string& message : curvatureWarnings(c)) tools::warn(kName, message);
          if (c.clamped_vertices > 0) {
            std::fprintf(stderr, "%s: %lld vertices with H^2 < K (umbilic or noisy): k1 = k2 = H\n",
                         kName, static_cast<long long>(c.clamped_vertices));
          }
          curvatures = {c.mean_curvature, c.gauss_curvature, c.k1, c.k2};
          setVertexField(in.mesh.cloud, "vertex_area", c.vertex_area, precision);
        } else {
          LocalFitOptions options = tools::localFitArguments(args, in, LocalFitMethod::Quadric);
          tools::orientLasUp(kName, args, in.las && !in.topology, options);
          const std::int64_t left_out = tools::keepOnlyClasses(kName, args, in);
          const tools::SamplingCheck sampling = tools::checkSampling(kName, in, options);
          tools::Timer timer("Fitting quadrics");
          LocalFitResult result = [&] {
            const tools::QuietPCLWarnings quiet;
            return fitLocalSurfaces(in.local(), in.topology, options);
          }();
          timer.done(in.points()->size());
          in.releaseLocal();
          result.failed_points -= left_out;  // -classes: not fitted by request
          tools::warnAboutLocalFit(kName, result);
          tools::warnAboutRadius(kName, sampling, options, result);
          curvatures = quadricFields(in.mesh.cloud, output, result, precision);
        }
        if (args.has("smooth")) {
          if (!in.topology)
            throw tools::UsageError("-smooth needs a mesh; this input is a point cloud");
          const double h = in.spacing();
          if (!(h > 0.0)) {
            throw std::runtime_error(
                "-smooth: the mesh has no edge of positive length to measure the "
                "time in");
          }
          HeatFlowParameters heat;
          heat.diffusion_time = smooth_time * h * h;
          Eigen::MatrixXd fields(curvatures.mean.size(), 4);
          fields << curvatures.mean, curvatures.gauss, curvatures.k1, curvatures.k2;
          tools::Timer timer("Smoothing curvatures");
          fields = smoothScalarFields(*in.topology, in.positions(), fields, heat);
          timer.done(static_cast<std::size_t>(fields.rows()));
          curvatures = {fields.col(0), fields.col(1), fields.col(2), fields.col(3)};
        }
        setCurvatureFields(in.mesh.cloud, curvatures, precision);
        if (color != "none") {
          const Eigen::VectorXd& values = color == "mean"    ? curvatures.mean
                                          : color == "gauss" ? curvatures.gauss
                                          : color == "k1"    ? curvatures.k1
                                                             : curvatures.k2;
          tools::setColorMapFields(
              kName, in.mesh.cloud, output,
              color == "mean" || color == "gauss" ? color + "_curvature" : color, values,
              colorize(values, ColorMap::Diverging, {percentile, 100.0 - percentile}));
        }
        tools::saveResult(kName, output, in, precision);
      });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
