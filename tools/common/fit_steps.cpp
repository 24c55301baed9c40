#include "common/fit_steps.h"

#include <pcl/common/point_tests.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>

#include "common/tool_output.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/features/fit_choices.h"
#include "pcl_ddg/features/robust_normal_estimation.h"
#include "pcl_ddg/io/cloud_pieces.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/result_warnings.h"
#include "pcl_ddg/search/point_spacing.h"
#include "pcl_ddg/tiling/byte_size.h"

namespace pcl_ddg {
namespace tools {

namespace {

const OptionSpelling kToolSpelling{"-viewpoint x,y,z", "-orient up"};

// -radius as written: a length, or a multiple of the input's spacing like "2.5h".
struct RadiusArgument {
  double value = 0.0;
  bool in_spacings = false;
};

RadiusArgument radiusArgument(const ToolArguments& args) {
  RadiusArgument radius;
  if (!args.has("radius")) return radius;
  std::string text = *args.value("radius");
  if (!text.empty() && text.back() == 'h') {
    text.pop_back();
    radius.in_spacings = true;
  }
  char* end = nullptr;
  radius.value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(radius.value > 0.0) || !std::isfinite(radius.value)) {
    throw UsageError("-radius must be a positive length or a multiple of the spacing like 2.5h");
  }
  return radius;
}

// -name x,y,z.
std::optional<Eigen::Vector3d> vectorArgument(const ToolArguments& args, const char* name) {
  if (!args.has(name)) return std::nullopt;
  const std::string text = *args.value(name);
  Eigen::Vector3d v;
  char* at = const_cast<char*>(text.c_str());
  for (int d = 0; d < 3; ++d) {
    char* end = nullptr;
    v[d] = std::strtod(at, &end);
    const char expected = d < 2 ? ',' : '\0';
    if (end == at || *end != expected || !std::isfinite(v[d]))
      throw UsageError(std::string("-") + name + " needs x,y,z, not '" + text + "'");
    at = end + (d < 2 ? 1 : 0);
  }
  return v;
}

std::optional<Eigen::Vector3d> viewpointArgument(const ToolArguments& args) {
  return vectorArgument(args, "viewpoint");
}

// -up x,y,z: a direction, normalised.
std::optional<Eigen::Vector3d> upArgument(const ToolArguments& args) {
  const std::optional<Eigen::Vector3d> up = vectorArgument(args, "up");
  if (up && !(up->norm() > 0.0)) throw UsageError("-up needs a non-zero direction");
  if (up) return up->normalized();
  return up;
}

}  // namespace

std::string describeNeighbourhood(const LocalFitOptions& options) {
  if (options.neighbourhood == NeighbourhoodKind::Grid && options.method == LocalFitMethod::PCA &&
      options.radius == 0.0) {
    const int side = 2 * gridWindowRadius(options.k) + 1;
    return "pixel grid, " + std::to_string(side) + " x " + std::to_string(side) +
           " window, running window sums";
  }
  const char* kind = options.neighbourhood == NeighbourhoodKind::MeshRings ? "mesh rings"
                     : options.neighbourhood == NeighbourhoodKind::Grid    ? "pixel grid"
                                                                           : "kd-tree";
  return std::string(kind) + ", " +
         (options.radius > 0.0 ? "radius " + std::to_string(options.radius)
                               : "k = " + std::to_string(options.k));
}

namespace {

/** The request as the command line gives it: the radius in its own unit (a length, or h). */
FitRequest fitRequest(const ToolArguments& args) {
  FitRequest request;
  if (args.has("k")) request.k = args.integer("k", 0);
  if (args.has("max_nn")) request.max_nn = args.integer("max_nn", 0);
  if (args.has("min_nn")) request.min_nn = args.integer("min_nn", 0);
  const RadiusArgument radius = radiusArgument(args);
  if (radius.value > 0.0) request.radius = radius.value;
  if (args.has("max_depth_jump")) request.max_depth_jump = args.number("max_depth_jump", 0.0);
  request.orient = args.value("orient");
  request.viewpoint = viewpointArgument(args).has_value();
  request.up = upArgument(args).has_value();
  return request;
}

}  // namespace

void checkLocalFitArguments(const ToolArguments& args) {
  usage([&] { checkFitRequest(fitRequest(args), kToolStyle); });
  classesArgument(args);
  requestedNeighbourhood(args);
}

std::optional<NormalOrientation> orientationArgument(const ToolArguments& args) {
  if (!args.has("orient")) return std::nullopt;
  return usage([&] { return chooseOrientation(*args.value("orient"), kToolStyle); });
}

std::optional<NeighbourhoodKind> requestedNeighbourhood(const ToolArguments& args) {
  if (!args.has("neighbours")) return std::nullopt;
  // The name only: whether the input has a mesh or a grid is checked when it is read.
  return usage(
      [&] { return chooseNeighbourhood(args.value("neighbours"), true, true, kToolStyle); });
}

LocalFitOptions localFitArguments(const ToolArguments& args, ToolInput& input,
                                  LocalFitMethod method) {
  checkLocalFitArguments(args);
  FitRequest request = fitRequest(args);
  LocalFitOptions options;
  options.method = method;
  const bool organized = !input.topology && input.points()->height > 1;
  options.neighbourhood = usage([&] {
    return chooseNeighbourhood(args.value("neighbours"), input.topology != nullptr, organized,
                               kToolStyle);
  });
  if (request.max_depth_jump && options.neighbourhood != NeighbourhoodKind::Grid)
    throw UsageError("-max_depth_jump applies to -neighbours grid");
  options.max_depth_jump = request.max_depth_jump.value_or(options.max_depth_jump);
  options.viewpoint = viewpointArgument(args);
  if (!options.viewpoint) options.viewpoint = input.sensor_pose.origin;
  options.up = upArgument(args);
  const RadiusArgument radius = radiusArgument(args);
  if (radius.value > 0.0 && radius.in_spacings) {
    double spacing = 1.0;
    if (input.topology) spacing = input.spacing();
    if (!input.topology) {
      Timer timer("Measuring the point spacing");
      spacing = input.spacing();
      timer.done(input.points()->size());
    }
    request.radius = radius.value * spacing;
  }
  applyNeighbourCounts(request, input.pointCount(), kToolStyle, options);
  return options;
}

namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

}  // namespace

PointSpacing warnAboutQuantisation(const char* tool_name,
                                   const pcl::PointCloud<pcl::PointXYZ>& points) {
  const PointSpacing spacing = measurePointSpacing(points);
  if (const auto message = quantisationWarning(spacing)) warn(tool_name, *message);
  return spacing;
}

SamplingCheck checkSampling(const char* tool_name, ToolInput& input,
                            const LocalFitOptions& options) {
  SamplingCheck check;
  if (input.topology) return check;  // a mesh's faces orient it; its edges are its spacing
  const pcl::PointCloud<pcl::PointXYZ>& points = *input.points();
  warnAboutQuantisation(tool_name, points);
  const BoundingBox box = input.bounds();
  if (const auto message = farViewpointWarning(box.min, box.max, options, kToolSpelling))
    warn(tool_name, *message);
  if (options.radius > 0.0) {
    const int wanted = options.min_neighbours > 0 ? static_cast<int>(options.min_neighbours) : 3;
    check.radius_counts = countRadiusNeighbours(points, options.radius, wanted);
    const RadiusNeighbourCounts& c = *check.radius_counts;
    std::fprintf(stderr,
                 "%s: points in a ball of radius %s (of %lld sampled): min %lld, median %lld, "
                 "%.1f %% under 3\n",
                 tool_name, number(options.radius).c_str(), static_cast<long long>(c.sampled),
                 static_cast<long long>(c.min), static_cast<long long>(c.median),
                 100.0 * c.share_under_3);
  }
  return check;
}

void warnAboutRadius(const char* tool_name, const SamplingCheck& check,
                     const LocalFitOptions& options, const LocalFitResult& result) {
  if (!check.radius_counts || result.failed_points == 0) return;
  const int wanted = options.min_neighbours > 0 ? static_cast<int>(options.min_neighbours) : 3;
  warn(
      tool_name,
      "-radius " + number(check.radius_counts->radius_for_min_neighbours) +
          " would give 90 % of the points at least " + std::to_string(wanted) + " neighbours" +
          (options.min_neighbours == 0 ? " (or -min_nn N: the N nearest where the ball holds fewer)"
                                       : ""));
}

LocalFitOptions outOfCoreFitArguments(const ToolArguments& args, LocalFitMethod method) {
  checkLocalFitArguments(args);
  if (requestedNeighbourhood(args).value_or(NeighbourhoodKind::KdTree) != NeighbourhoodKind::KdTree)
    throw UsageError("-memory fits clouds with kd-tree neighbourhoods (-neighbours kdtree)");
  LocalFitOptions options;
  options.method = method;
  options.neighbourhood = NeighbourhoodKind::KdTree;
  options.viewpoint = viewpointArgument(args);
  options.up = upArgument(args);
  if (args.has("classes")) throw UsageError("-classes is not available with -memory");
  if (args.has("min_nn"))
    throw UsageError(
        "-min_nn is not available with -memory (a tile's halo is certified for the "
        "ball)");
  const RadiusArgument radius = radiusArgument(args);
  if (radius.in_spacings)
    throw UsageError("with -memory, -radius is a length (a multiple of h needs the whole cloud)");
  // The tiles check k against the points they hold.
  applyNeighbourCounts(fitRequest(args), std::numeric_limits<std::int64_t>::max(), kToolStyle,
                       options);
  return options;
}

std::vector<int> classesArgument(const ToolArguments& args) {
  std::vector<int> classes;
  if (!args.has("classes")) return classes;
  const std::string text = *args.value("classes");
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    char* end = nullptr;
    const long value = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || value < 0 || value > 255)
      throw UsageError(
          "-classes needs classification values 0-255 separated by commas, like 2,6"
          " (not '" +
          text + "')");
    classes.push_back(static_cast<int>(value));
    at = comma + 1;
  }
  return classes;
}

std::int64_t keepOnlyClasses(const char* tool_name, const ToolArguments& args, ToolInput& input) {
  const std::vector<int> classes = classesArgument(args);
  if (classes.empty()) return 0;
  if (input.topology) throw UsageError("-classes applies to point clouds (a LAS file), not meshes");
  if (!hasVertexField(input.mesh.cloud, "classification"))
    throw std::runtime_error(
        "-classes needs a classification field (a LAS file); the input has "
        "none");
  const Eigen::VectorXd classification = vertexScalarField(input.mesh.cloud, "classification");
  input.separateLocal();  // the points left out become NaN in the fits only, not in the output
  std::int64_t left_out = 0;
  for (Eigen::Index i = 0; i < classification.size(); ++i) {
    if (std::find(classes.begin(), classes.end(), static_cast<int>(classification[i])) !=
        classes.end())
      continue;
    pcl::PointXYZ& p = (*input.points())[static_cast<std::size_t>(i)];
    p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
    if (input.local().positions)
      input.local().positions->col(i).setConstant(std::numeric_limits<double>::quiet_NaN());
    ++left_out;
  }
  const std::int64_t fitted = classification.size() - left_out;
  if (fitted == 0)
    throw std::runtime_error("no point is of the classes -classes " + *args.value("classes"));
  input.points()->is_dense = false;
  std::fprintf(stderr, "%s: -classes %s: fitting %lld of %lld points (NaN elsewhere)\n", tool_name,
               args.value("classes")->c_str(), static_cast<long long>(fitted),
               static_cast<long long>(classification.size()));
  return left_out;
}

void orientLasUp(const char* tool_name, const ToolArguments& args, bool las_input,
                 LocalFitOptions& options) {
  if (!las_input || args.has("viewpoint") || args.has("orient")) return;
  options.orientation = NormalOrientation::Up;
  std::fprintf(stderr,
               "%s: a LAS file: normals oriented up (n . z >= 0, as PDAL's filters.normal; "
               "-viewpoint or -orient chooses otherwise)\n",
               tool_name);
}

std::uint64_t memoryArgument(const ToolArguments& args) {
  try {
    return parseByteSize(*args.value("memory"));
  } catch (const pcl::BadArgumentException& e) {
    throw UsageError("-memory needs " + errorDescription(e));
  }
}

namespace {

void fitOutOfCore(const char* tool_name, const ToolArguments& args, const std::string& input,
                  const std::string& output, const LocalFitOptions& options,
                  const ResultFields& fields) {
  OutOfCoreOptions limits;
  limits.memory_budget = memoryArgument(args);
  const char* fits = options.method == LocalFitMethod::PCA       ? "planes"
                     : options.method == LocalFitMethod::Quadric ? "quadrics"
                                                                 : "robust planes";
  Timer timer(std::string("Fitting ") + fits + " out of core (budget " + *args.value("memory") +
              ")");
  const OutOfCoreReport report = [&] {
    const QuietPCLWarnings quiet;
    return fitCloudFileOutOfCore(input, output, options, limits, fields);
  }();
  timer.done(static_cast<std::size_t>(report.points));
  std::fprintf(stderr,
               "%s: %zu tiles of at most %lld points, %lld halo growths, %lld points fitted "
               "apart, at most %lld points fitted at once\n",
               tool_name, report.tiling.tiles, static_cast<long long>(report.points_per_tile),
               static_cast<long long>(report.tiling.halo_growths),
               static_cast<long long>(report.tiling.far_points),
               static_cast<long long>(report.tiling.largest_gather));
  LocalFitResult counts;
  counts.failed_points = report.failed_points;
  counts.fallback_points = report.fallback_points;
  warnAboutLocalFit(tool_name, counts);
}

ResultFields outOfCoreFields(const std::string& output_path, FieldPrecision precision,
                             const PieceFields& add) {
  return [output_path, precision, add](CloudPiece& piece, const LocalFitResult& fit) {
    // As loading (float x y z for PCL), adding the fields, and saving do in memory.
    setVertexCoordinates(piece.cloud, piece.positions, FieldPrecision::Float);
    add(piece.cloud, output_path, fit);
    setVertexCoordinates(piece.cloud, piece.positions,
                         coordinatePrecision(piece.coordinate_precision, precision));
  };
}

}  // namespace

int fitEachInputOutOfCore(const char* tool_name, const ToolArguments& args,
                          const LocalFitOptions& options, FieldPrecision precision,
                          const PieceFields& add) {
  memoryArgument(args);  // checked before any file is read
  return forEachInput(
      args, tool_name, {"ply", "pcd", "las", "laz"},
      [&](const std::string& input, const std::string& output) {
        LocalFitOptions for_input = options;
        const std::string ext = fileExtension(input);
        orientLasUp(tool_name, args, ext == "las" || ext == "laz", for_input);
        // Robust's default k, as in memory: 96 or every point if fewer.
        if (for_input.method == LocalFitMethod::Robust && !args.has("k") && for_input.radius == 0.0)
          for_input.k =
              defaultNeighbours(LocalFitMethod::Robust, CloudPieceReader(input).layout().points);
        fitOutOfCore(tool_name, args, input, output, for_input,
                     outOfCoreFields(output, precision, add));
      });
}

QuietPCLWarnings::QuietPCLWarnings() : level_(pcl::console::getVerbosityLevel()) {
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
}

QuietPCLWarnings::~QuietPCLWarnings() {
  pcl::console::setVerbosityLevel(static_cast<pcl::console::VERBOSITY_LEVEL>(level_));
}

void warnAboutLocalFit(const char* tool_name, const LocalFitResult& result) {
  for (const std::string& message : fitResultWarnings(result.failed_points, result.fallback_points))
    warn(tool_name, message);
}

}  // namespace tools
}  // namespace pcl_ddg
