#include "viewer/viewer_model.h"

#include <pcl/console/time.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/fit_steps.h"
#include "common/tool_output.h"
#include "pcl_ddg/features/neighbourhood_comparison.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/surface/mesh_normals.h"
#include "pcl_ddg/surface/mesh_smoothing.h"
#include "pcl_ddg/surface/smoothing_steps.h"

namespace pcl_ddg {
namespace viewer {
namespace {

constexpr double kDegreesPerRadian = 57.295779513082320876798;

std::string stepKey(const SmoothingStep& s) {
  std::ostringstream key;
  key << static_cast<int>(s.method) << 'm' << s.time_step << 't' << static_cast<int>(s.weights)
      << 'w' << (s.frozen ? 'f' : 'r') << ';';
  return key.str();
}

std::string versionOf(const std::vector<SmoothingStep>& steps) {
  std::string version = "input;";
  for (const SmoothingStep& s : steps) version += stepKey(s);
  return version;
}

// Scalar fields of the file that can be coloured (not coordinates, normals or colours).
std::vector<std::string> colourableProperties(const pcl::PCLPointCloud2& cloud) {
  static const char* kSkipped[] = {"x",        "y",   "z",     "normal_x", "normal_y",
                                   "normal_z", "nx",  "ny",    "nz",       "rgb",
                                   "rgba",     "red", "green", "blue",     "alpha"};
  std::vector<std::string> names;
  for (const pcl::PCLPointField& f : cloud.fields) {
    if (f.count != 1 ||
        std::find(std::begin(kSkipped), std::end(kSkipped), f.name) != std::end(kSkipped)) {
      continue;
    }
    names.push_back(f.name);
  }
  return names;
}

std::string count(std::int64_t n, const std::string& what) {
  return std::to_string(n) + " " + what;
}

}  // namespace

ViewerModel::ViewerModel(tools::ToolInput input, std::string path)
    : input_(std::move(input)), path_(std::move(path)) {
  capabilities_.is_mesh = static_cast<bool>(input_.topology);
  capabilities_.points = static_cast<int>(input_.pointCount());
  capabilities_.properties = colourableProperties(input_.mesh.cloud);
  if (vertexColorLayout(input_.mesh.cloud)) {
    capabilities_.has_colors = true;
    file_colors_ = vertexColors(input_.mesh.cloud);
  }
  const Eigen::AlignedBox3d box = finiteBounds(input_.positions());
  diagonal_ = box.isEmpty() ? 0.0 : box.diagonal().norm();
  input_positions_ = std::make_shared<const Eigen::Matrix3Xd>(input_.positions());
  positions_["input;"] = input_positions_;
  // The input's own positions from here on are positions_'s: local() holds the ToolInput's.
  clouds_["input;"] = input_.local();
  spacing_ = input_.spacing();
  if (!(spacing_ > 0.0)) spacing_ = 1.0;
}

ViewerModel::Positions ViewerModel::positionsAfter(const std::vector<SmoothingStep>& steps,
                                                   std::vector<std::string>& warnings,
                                                   bool& refused) {
  const std::string version = versionOf(steps);
  if (const auto it = positions_.find(version); it != positions_.end()) return it->second;
  std::vector<SmoothingStep> before(steps.begin(), steps.end() - 1);
  const Positions start = positionsAfter(before, warnings, refused);
  if (refused) return start;

  const SmoothingStep& step = steps.back();
  MeshSmoothingParameters parameters;
  parameters.scheme = step.method;
  parameters.weights = step.weights == SmoothingWeights::Cotan ? LaplacianWeights::Cotangent
                                                               : LaplacianWeights::Uniform;
  // Taubin's lambda 0.5 and mu -0.53 are steps of an operator averaged by degree.
  parameters.average =
      step.weights == SmoothingWeights::Umbrella || step.method == SmoothingScheme::Taubin
          ? FlowAverage::Degree
          : FlowAverage::Area;
  // Frozen: the Laplacian of the surface where this run of frozen steps began, so a run of n
  // frozen steps is one smoothing of n iterations from there; rebuilt: that of this step's start.
  Positions from = start;
  if (step.frozen) {
    std::size_t first = steps.size() - 1;
    while (first > 0 && steps[first - 1] == step) --first;
    parameters.iterations = static_cast<int>(steps.size() - first);
    from = positionsAfter(std::vector<SmoothingStep>(steps.begin(), steps.begin() + first),
                          warnings, refused);
    parameters.weight_update = WeightUpdate::Frozen;
  } else {
    parameters.weight_update = WeightUpdate::EveryIteration;
  }
  // Steps averaged by area are in h^2 of the input, so that a step means the same all along.
  const bool per_area = parameters.average == FlowAverage::Area;
  const double h2 = spacing_ * spacing_;
  RelativeSteps relative;
  if (step.method != SmoothingScheme::Taubin)
    relative.step = per_area ? step.time_step * h2 : step.time_step;
  relative.absolute_time = per_area;
  relative.allow_unstable = true;  // an explicit step is capped below
  try {
    const ResolvedSteps resolved = resolveSteps(*input_.topology, *from, relative, parameters);
    if (resolved.unstable) {
      if (step.method == SmoothingScheme::Taubin)
        throw std::runtime_error("Taubin's steps exceed the stability bound on this mesh");
      // Forward Euler beyond its stability bound blows up: the step is capped there, and said so.
      parameters.time_step = 0.9 * resolved.bound * resolved.unit;
      std::ostringstream note;
      note.precision(3);
      note << "explicit step capped at the stability bound, "
           << 0.9 * resolved.bound / (per_area ? h2 : 1.0) << (per_area ? " h^2" : "");
      warnings.push_back(note.str());
    }
    auto result = std::make_shared<const Eigen::Matrix3Xd>(
        smoothMeshPositions(*input_.topology, *from, parameters));
    positions_[version] = result;
    return result;
  } catch (const std::exception& e) {
    warnings.push_back(std::string("smoothing step refused: ") + e.what());
    refused = true;
    return start;
  }
}

LocalFitResult ViewerModel::fit(LocalFitMethod method, const ViewerState& state,
                                const LocalCloud& cloud) const {
  LocalFitOptions options;
  options.method = method;
  options.neighbourhood = state.neighbours;
  options.k = state.k;
  options.viewpoint = input_.sensor_pose.origin;
  // Aerial LiDAR has no single viewpoint: up, as the tools orient a LAS file by default.
  if (input_.las && !input_.topology) options.orientation = NormalOrientation::Up;
  const tools::QuietPCLWarnings quiet;
  return fitLocalSurfaces(cloud, input_.topology, options);
}

const LocalCloud& ViewerModel::cloudOf(const std::string& version, const Positions& positions) {
  const auto it = clouds_.find(version);
  if (it != clouds_.end()) return it->second;
  return clouds_[version] = makeLocalCloud(*positions, clouds_.at("input;").origin);
}

std::shared_ptr<const Eigen::Matrix3Xd> ViewerModel::normalsOf(NormalMethod method,
                                                               const ViewerState& state,
                                                               const std::string& version,
                                                               const Positions& positions,
                                                               std::vector<std::string>& warnings) {
  const bool fitted = !isMeshMethod(method);
  std::string key = version + methodName(method);
  if (fitted) {
    key += std::string("/") + neighbourhoodName(state.neighbours) + "/" + std::to_string(state.k);
  }
  if (const auto it = normals_.find(key); it != normals_.end()) return it->second;

  std::shared_ptr<const Eigen::Matrix3Xd> normals;
  std::int64_t invalid = 0, fallback = 0;
  if (!fitted) {
    MeshNormalOptions options;
    options.weighting = chooseNormalWeighting(methodName(method), "method", kToolStyle);
    MeshNormals result = computeMeshNormals(*input_.topology, *positions, options);
    invalid = result.invalid_vertices;
    if (method == NormalMethod::MeanCurvature) fallback = result.fallback_vertices;
    normals = std::make_shared<const Eigen::Matrix3Xd>(std::move(result.normals));
  } else {
    const LocalFitResult result =
        fit(chooseFitMethod(methodName(method), kToolStyle), state, cloudOf(version, positions));
    invalid = result.failed_points;
    fallback = result.fallback_points;
    normals = std::make_shared<const Eigen::Matrix3Xd>(tools::normalsOf(result.normals));
  }
  if (invalid > 0) warnings.push_back(count(invalid, "vertices without a normal (NaN)"));
  if (fallback > 0) {
    warnings.push_back(count(fallback, method == NormalMethod::MeanCurvature
                                           ? "flat vertices took the area normal"
                                           : "points fell back to the PCA normal"));
  }
  normals_[key] = normals;
  return normals;
}

Eigen::VectorXd ViewerModel::fieldOf(const ViewerState& state, const std::string& version,
                                     const Positions& positions, const Eigen::Matrix3Xd& normals,
                                     std::string& label, ColorMap& map,
                                     std::vector<std::string>& warnings) {
  const std::string& field = state.field;
  map = ColorMap::Diverging;
  const bool curvature = field == "mean" || field == "gauss" || field == "k1" || field == "k2";
  if (curvature) {
    const char* names[] = {"mean curvature H", "Gaussian curvature K", "principal curvature k1",
                           "principal curvature k2"};
    const int which = field == "mean" ? 0 : field == "gauss" ? 1 : field == "k1" ? 2 : 3;
    const bool cotan = isMesh() && isMeshMethod(state.method);
    label = std::string(names[which]) + (which == 1 ? " (1/length^2), " : " (1/length), ") +
            (cotan ? "cotan" : "quadric fit, k = " + std::to_string(state.k));
    const std::string key =
        version + field +
        (cotan ? "/cotan"
               : "/quadric/" + std::to_string(state.k) +
                     (state.neighbours == NeighbourhoodKind::MeshRings ? "rings" : "kdtree"));
    if (const auto it = fields_.find(key); it != fields_.end()) return it->second;
    Eigen::VectorXd values[4];
    if (cotan) {
      VertexCurvatures c = computeCurvatures(*input_.topology, *positions);
      values[0] = c.mean_curvature;
      values[1] = c.gauss_curvature;
      values[2] = c.k1;
      values[3] = c.k2;
      if (c.invalid_vertices > 0)
        warnings.push_back(count(c.invalid_vertices, "vertices without curvature (NaN)"));
    } else {
      const LocalFitResult quadric =
          fit(LocalFitMethod::Quadric, state, cloudOf(version, positions));
      const Eigen::Index n = static_cast<Eigen::Index>(quadric.curvatures.size());
      for (auto& v : values) v.resize(n);
      for (Eigen::Index i = 0; i < n; ++i) {
        const double k1 = quadric.curvatures[i].pc1, k2 = quadric.curvatures[i].pc2;
        values[0][i] = 0.5 * (k1 + k2);
        values[1][i] = k1 * k2;
        values[2][i] = k1;
        values[3][i] = k2;
      }
    }
    const char* keys[] = {"mean", "gauss", "k1", "k2"};
    const std::string prefix = key.substr(0, version.size());
    const std::string suffix = key.substr(version.size() + field.size());
    for (int i = 0; i < 4; ++i) fields_[prefix + keys[i] + suffix] = values[i];
    return values[which];
  }
  if (field == "angle") {
    // Against area normals on meshes and PCA on clouds, or, when those are shown, the next best.
    NormalMethod reference = isMesh() ? NormalMethod::Area : NormalMethod::PCA;
    if (state.method == reference)
      reference = isMesh() ? NormalMethod::MeanCurvature : NormalMethod::Quadric;
    if (state.reference) reference = *state.reference;
    label = std::string("angle to ") + methodName(reference) + " normals (degrees)";
    map = ColorMap::Sequential;
    const auto other = normalsOf(reference, state, version, positions, warnings);
    Eigen::VectorXd angle(normals.cols());
    for (Eigen::Index i = 0; i < normals.cols(); ++i) {
      angle[i] =
          std::acos(std::clamp(normals.col(i).dot(other->col(i)), -1.0, 1.0)) * kDegreesPerRadian;
    }
    return angle;
  }
  if (field == "compare") {
    const NormalMethod method =
        state.method == NormalMethod::Quadric ? NormalMethod::Quadric : NormalMethod::PCA;
    label = std::string("mesh rings vs kd-tree, ") + methodName(method) +
            " k = " + std::to_string(state.k) + " (degrees)";
    map = ColorMap::Sequential;
    const std::string key = version + "compare/" + methodName(method) + std::to_string(state.k);
    if (const auto it = fields_.find(key); it != fields_.end()) return it->second;
    LocalFitOptions options;
    options.method = method == NormalMethod::PCA ? LocalFitMethod::PCA : LocalFitMethod::Quadric;
    options.k = state.k;
    const tools::QuietPCLWarnings quiet;
    const NeighbourhoodComparison comparison =
        compareNeighbourhoods(cloudOf(version, positions), input_.topology, options);
    std::ostringstream summary;
    summary.precision(3);
    summary << "rings vs kd-tree: mean " << comparison.summary.mean << " deg, "
            << 100.0 * comparison.summary.share_over_5 << "% over 5 deg";
    warnings.push_back(summary.str());
    return fields_[key] = comparison.angle_difference;
  }
  // A property of the file.
  label = field + " (from the file)";
  map = ColorMap::Sequential;
  return vertexScalarField(input_.mesh.cloud, field);
}

Frame ViewerModel::compute(const ViewerState& state) {
  pcl::console::TicToc clock;
  clock.tic();
  Frame frame;
  frame.state = state;
  frame.positions = positionsAfter(state.steps, frame.warnings, frame.step_refused);
  // After a refused step the frame shows the steps that succeeded.
  while (frame.step_refused && !positions_.count(versionOf(frame.state.steps))) {
    frame.state.steps.pop_back();
  }
  const std::string shown = versionOf(frame.state.steps);
  frame.normals = normalsOf(state.method, frame.state, shown, frame.positions, frame.warnings);
  // Glyphs a point spacing long, but at least 1 % of the object's size: visible on a 500 m
  // terrain sampled every metre as on a finely meshed 10 cm part. Longer than the spacing, they are
  // drawn as far apart as they are long (every n-th point, n their length over the spacing,
  // squared, on a surface), and never more than about 20,000.
  frame.glyph_length = std::max(spacing_, 0.01 * diagonal_);
  const double apart = frame.glyph_length / spacing_;
  frame.glyph_every = std::max<Eigen::Index>(
      {1, static_cast<Eigen::Index>(apart * apart), frame.positions->cols() / 20000});
  const Eigen::Index n = frame.positions->cols();
  if (state.field == "none") {
    frame.colors = VertexColors::Constant(3, n, 200);
    frame.field_label = "";
  } else if (state.field == "rgb") {
    frame.colors = file_colors_;
    frame.field_label = "";
  } else {
    frame.field = fieldOf(frame.state, shown, frame.positions, *frame.normals, frame.field_label,
                          frame.color_map, frame.warnings);
    frame.range = colorRange(frame.field, frame.color_map);
    frame.colors = colorizeWithin(frame.field, frame.color_map, frame.range);
  }
  frame.compute_ms = clock.toc();
  return frame;
}

}  // namespace viewer
}  // namespace pcl_ddg
