// Every tool option that changes numbers, against the library call it stands for. Each table row
// runs the tool with the option and asserts two things:
//   1. the output equals the library call with that setting: bit for bit where -precision double
//      writes doubles, to float rounding where the tool writes floats, byte for byte for PNGs;
//   2. that setting gives other numbers than the one the tool uses without the option (beyond
//      float rounding), so a tool that ignored or misread the option fails (1).
// The library calls are written out here from the tools' documented meaning of each option, not
// taken from the tools' own code.
#include <gtest/gtest.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/features/neighbourhood_comparison.h"
#include "pcl_ddg/features/normal_orientation.h"
#include "pcl_ddg/features/robust_normal_estimation.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/render/color_bar.h"
#include "pcl_ddg/render/color_map.h"
#include "pcl_ddg/render/mesh_render.h"
#include "pcl_ddg/surface/grid_smoothing.h"
#include "pcl_ddg/surface/mesh_normals.h"
#include "pcl_ddg/surface/mesh_smoothing.h"
#include "pcl_ddg/surface/scalar_field_smoothing.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

// An input as the tools read it: readMeshFile's exact coordinates, the topology of a mesh, the
// same points about their local origin (an organized cloud keeps its grid and its sensor).
struct Input {
  MeshFile file;
  std::shared_ptr<const MeshTopology> topology;  ///< null for a cloud
  LocalCloud local;
  pcl::PointCloud<pcl::PointXYZ>::Ptr points;  ///< local's float points
  double h = 0.0;  ///< mean edge length of a mesh: the unit of -radius 2.5h and -lambda_dt

  const Eigen::Matrix3Xd& positions() const { return file.positions; }
};

Input readInput(const std::string& path) {
  Input in;
  in.file = readMeshFile(path);
  const Eigen::Matrix3Xd& x = in.file.positions;
  const bool mesh = !in.file.mesh.polygons.empty();
  in.local =
      makeLocalCloud(x, !mesh && in.file.mesh.cloud.height > 1 ? in.file.mesh.cloud.width : 0);
  in.points = std::const_pointer_cast<pcl::PointCloud<pcl::PointXYZ>>(in.local.points);
  if (mesh) {
    in.topology = std::make_shared<const MeshTopology>(in.file.mesh);
    in.h = meanEdgeLength(*in.topology, x);
  }
  in.points->sensor_origin_.head<3>() =
      (in.file.sensor_pose.origin - in.local.origin).cast<float>();
  in.points->sensor_orientation_ = in.file.sensor_pose.orientation.cast<float>();
  return in;
}

// Named per-vertex values: row r holds the field names[r].
struct Fields {
  std::vector<std::string> names;
  Eigen::MatrixXd values;
};

// x, y, z come from readMeshFile's exact positions: its PCL cloud holds them as float.
Fields readFields(const std::string& path, const std::vector<std::string>& names) {
  const MeshFile file = readMeshFile(path);
  Fields f{names, Eigen::MatrixXd(names.size(), file.positions.cols())};
  for (std::size_t r = 0; r < names.size(); ++r) {
    const std::string& name = names[r];
    if (name == "x" || name == "y" || name == "z") {
      f.values.row(r) = file.positions.row(name[0] - 'x');
    } else {
      f.values.row(r) = vertexScalarField(file.mesh.cloud, name).transpose();
    }
  }
  return f;
}

Eigen::MatrixXd roundedToFloat(const Eigen::MatrixXd& values) {
  return values.cast<float>().cast<double>();
}

// How far apart two sets of values are. NaN equals NaN (the tools write NaN where the library
// has none), NaN against a number is a difference; max is the largest finite one, relative to
// the largest finite magnitude in either set.
struct Difference {
  std::int64_t entries = 0;
  double max_relative = 0.0;
};

Difference difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Difference d;
  double scale = 0.0, largest = 0.0;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    const double x = a.data()[i], y = b.data()[i];
    if (std::isnan(x) && std::isnan(y)) continue;
    if (x == y) {
      if (std::isfinite(x)) scale = std::max(scale, std::abs(x));
      continue;
    }
    ++d.entries;
    if (std::isfinite(x) && std::isfinite(y)) {
      scale = std::max({scale, std::abs(x), std::abs(y)});
      largest = std::max(largest, std::abs(x - y));
    } else {
      largest = std::numeric_limits<double>::infinity();
    }
  }
  d.max_relative = scale > 0.0 ? largest / scale : largest;
  return d;
}

// Rows of `f` named as in `names` (the fields two results share).
Eigen::MatrixXd rowsNamed(const Fields& f, const std::vector<std::string>& names) {
  Eigen::MatrixXd rows(names.size(), f.values.cols());
  for (std::size_t r = 0; r < names.size(); ++r) {
    const auto at = std::find(f.names.begin(), f.names.end(), names[r]);
    rows.row(r) = f.values.row(at - f.names.begin());
  }
  return rows;
}

// Beyond float rounding (6e-8 relative): the option's effect cannot be an artefact of the output.
constexpr double kMinimumEffect = 1e-6;

enum class Match { Exact, FloatRounding };

// One option of a tool: its command-line options, the library's result with that setting, and
// the library's result with the setting the tool takes without the option (empty for the row that
// pins the tool's default). input overrides the table's input file.
struct OptionCase {
  std::string options;
  std::function<Fields()> library;
  std::function<Fields()> without_option;
  std::string input;
};

// Runs every row; see the file comment.
void checkOptionTable(const char* tool, const std::string& input, const std::string& output,
                      const std::string& fixed_options, Match match,
                      const std::vector<OptionCase>& table) {
  for (const OptionCase& row : table) {
    SCOPED_TRACE(std::string(tool) + " " + row.options);
    std::filesystem::remove(output);
    const ToolRun run = runTool(tool, (row.input.empty() ? input : row.input) + " " + output + " " +
                                          fixed_options + " " + row.options);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const Fields expected = row.library();
    const Fields written = readFields(output, expected.names);
    const Eigen::MatrixXd reference =
        match == Match::Exact ? expected.values : roundedToFloat(expected.values);
    const Difference tool_vs_library = difference(written.values, reference);
    EXPECT_EQ(tool_vs_library.entries, 0)
        << "the tool's output is not the library's with this setting (largest relative "
           "difference "
        << tool_vs_library.max_relative << ")";
    if (!row.without_option) continue;
    // The fields both settings write (a quadric writes more fields than the cotangent formulas).
    const Fields other = row.without_option();
    std::vector<std::string> shared;
    for (const std::string& name : expected.names) {
      if (std::find(other.names.begin(), other.names.end(), name) != other.names.end())
        shared.push_back(name);
    }
    ASSERT_FALSE(shared.empty());
    const Difference effect = difference(rowsNamed(expected, shared), rowsNamed(other, shared));
    std::printf("%s %s: %lld of %lld values differ from the default's, by up to %.3g relative\n",
                std::filesystem::path(tool).filename().c_str(), row.options.c_str(),
                static_cast<long long>(effect.entries),
                static_cast<long long>(shared.size() * other.values.cols()), effect.max_relative);
    EXPECT_GT(effect.max_relative, kMinimumEffect)
        << "this setting gives the default's numbers: the test could not see the option ignored";
  }
}

// f computed on the first call only: many rows share a setting (mostly the default).
std::function<Fields()> once(std::function<Fields()> f) {
  auto cache = std::make_shared<std::optional<Fields>>();
  return [f, cache] {
    if (!*cache) *cache = f();
    return **cache;
  };
}

class ToolOptions : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

// ---------------------------------------------------------------------------------------------
// pcl_ddg_normals

Fields meshNormals(const Input& in, NormalWeighting weighting, double epsilon = -1.0) {
  MeshNormalOptions options;
  options.weighting = weighting;
  options.epsilon = epsilon;
  return {{"nx", "ny", "nz"}, computeMeshNormals(*in.topology, in.positions(), options).normals};
}

// The fit the tools run on a mesh: oriented like its faces, the file's viewpoint (the origin).
LocalFitOptions meshFit(LocalFitMethod method, NeighbourhoodKind neighbourhood, int k) {
  LocalFitOptions options;
  options.method = method;
  options.neighbourhood = neighbourhood;
  options.k = k;
  options.viewpoint = Eigen::Vector3d::Zero();
  return options;
}

LocalFitOptions withRadius(LocalFitOptions options, double radius, unsigned int max_nn = 64,
                           unsigned int min_nn = 0) {
  options.radius = radius;
  options.max_neighbours = max_nn;
  options.min_neighbours = min_nn;
  return options;
}

// Normals (float, as PCL's estimators give them) and PCL's curvature field.
Fields fittedNormals(const Input& in, const LocalFitOptions& options) {
  const LocalFitResult r = fitLocalSurfaces(in.local, in.topology, options);
  Fields f{{"nx", "ny", "nz", "curvature"}, Eigen::MatrixXd(4, r.normals.size())};
  for (std::size_t i = 0; i < r.normals.size(); ++i) {
    const pcl::Normal& n = r.normals[i];
    f.values.col(i) << n.normal_x, n.normal_y, n.normal_z, n.curvature;
  }
  return f;
}

std::string number(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

TEST_F(ToolOptions, NormalsEqualTheLibraryForEveryMethodAndNeighbourhood) {
  const std::string file = sharedData("meshes/bumpy.off");
  const Input in = readInput(file);
  // -epsilon at the median |M^-1 L x| (= 2|H n|): about half the vertices count as flat.
  const Eigen::Matrix3Xd hn = meanCurvatureNormal(*in.topology, in.positions());
  std::vector<double> magnitudes(hn.cols());
  for (Eigen::Index v = 0; v < hn.cols(); ++v) magnitudes[v] = 2.0 * hn.col(v).norm();
  std::nth_element(magnitudes.begin(), magnitudes.begin() + magnitudes.size() / 2,
                   magnitudes.end());
  const double epsilon = magnitudes[magnitudes.size() / 2];
  MeshNormalOptions flat;
  flat.weighting = NormalWeighting::MeanCurvature;
  flat.epsilon = epsilon;
  const std::int64_t fallback =
      computeMeshNormals(*in.topology, in.positions(), flat).fallback_vertices;
  EXPECT_GT(fallback, hn.cols() / 4);
  EXPECT_LT(fallback, 3 * hn.cols() / 4);

  using W = NormalWeighting;
  using K = NeighbourhoodKind;
  const auto pca = [&](K kind, int k) { return meshFit(LocalFitMethod::PCA, kind, k); };
  const auto quadric = [&](K kind, int k) { return meshFit(LocalFitMethod::Quadric, kind, k); };
  const auto normals = [&](W w, double e = -1.0) {
    return [&in, w, e] { return meshNormals(in, w, e); };
  };
  const auto fitted = [&](LocalFitOptions o) { return [&in, o] { return fittedNormals(in, o); }; };
  const double h = in.h;
  const auto area = once(normals(W::Area)), uniform = once(normals(W::Uniform));
  const auto mean_curvature = once(normals(W::MeanCurvature));
  const auto pca16 = once(fitted(pca(K::MeshRings, 16)));
  const auto ball = once(fitted(withRadius(pca(K::MeshRings, 16), 2.5 * h)));
  const auto quadric20 = once(fitted(quadric(K::MeshRings, 20)));
  const auto robust96 =
      once(fitted(meshFit(LocalFitMethod::Robust, K::MeshRings, kRobustNormalNeighbours)));
  const std::vector<OptionCase> table = {
      {"", area, {}},  // a mesh's default: area weighting
      {"-method uniform", uniform, area},
      {"-method area", area, uniform},  // the default: the row above pins it
      {"-method angle", normals(W::Angle), area},
      {"-method mean_curvature", mean_curvature, area},
      {"-method mean_curvature -epsilon " + number(epsilon), normals(W::MeanCurvature, epsilon),
       mean_curvature},
      {"-method pca", pca16, area},
      {"-method pca -k 8", fitted(pca(K::MeshRings, 8)), pca16},
      {"-method pca -neighbours kdtree", fitted(pca(K::KdTree, 16)), pca16},
      {"-method pca -radius 2.5h", ball, pca16},
      {"-method pca -radius 2.5h -max_nn 8", fitted(withRadius(pca(K::MeshRings, 16), 2.5 * h, 8)),
       ball},
      {"-method pca -neighbours kdtree -radius 0.7h -min_nn 12",
       fitted(withRadius(pca(K::KdTree, 16), 0.7 * h, 64, 12)),
       fitted(withRadius(pca(K::KdTree, 16), 0.7 * h))},
      {"-method quadric", quadric20, pca16},
      {"-method quadric -k 30", fitted(quadric(K::MeshRings, 30)), quadric20},
      // robust's own default neighbourhood (kRobustNormalNeighbours), the tool's as the library's
      {"-method robust", robust96, pca16},
      {"-method robust -k 40", fitted(meshFit(LocalFitMethod::Robust, K::MeshRings, 40)), robust96},
  };
  checkOptionTable(PCL_DDG_NORMALS_TOOL, file, path("n.ply"), "-precision double", Match::Exact,
                   table);
}

// ---------------------------------------------------------------------------------------------
// pcl_ddg_curvature

const std::vector<std::string> kCurvatureNames = {"mean_curvature", "gauss_curvature", "k1", "k2"};

Fields cotanCurvatures(const Input& in, MassType mass) {
  const VertexCurvatures c = computeCurvatures(*in.topology, in.positions(), mass);
  Fields f{kCurvatureNames, Eigen::MatrixXd(4, c.k1.size())};
  f.values << c.mean_curvature.transpose(), c.gauss_curvature.transpose(), c.k1.transpose(),
      c.k2.transpose();
  f.names.push_back("vertex_area");
  f.values.conservativeResize(5, Eigen::NoChange);
  f.values.row(4) = c.vertex_area.transpose();
  return f;
}

// H = (k1 + k2) / 2 and K = k1 k2 from the quadric's principal curvatures, with its k1 direction
// and normal.
Fields quadricCurvatures(const Input& in, const LocalFitOptions& options) {
  const LocalFitResult r = fitLocalSurfaces(in.local, in.topology, options);
  const auto n = static_cast<Eigen::Index>(r.curvatures.size());
  Eigen::VectorXd k1(n), k2(n);
  Fields f{{"k1_direction_x", "k1_direction_y", "k1_direction_z", "nx", "ny", "nz"},
           Eigen::MatrixXd(10, n)};
  for (Eigen::Index i = 0; i < n; ++i) {
    const pcl::PrincipalCurvatures& p = r.curvatures[i];
    const pcl::Normal& normal = r.normals[i];
    k1[i] = p.pc1;
    k2[i] = p.pc2;
    f.values.col(i).head<6>() << p.principal_curvature_x, p.principal_curvature_y,
        p.principal_curvature_z, normal.normal_x, normal.normal_y, normal.normal_z;
  }
  f.values.row(6) = (0.5 * (k1 + k2)).transpose();
  f.values.row(7) = k1.cwiseProduct(k2).transpose();
  f.values.row(8) = k1.transpose();
  f.values.row(9) = k2.transpose();
  f.names.insert(f.names.end(), kCurvatureNames.begin(), kCurvatureNames.end());
  return f;
}

// -smooth t: the four fields by the implicit heat flow for t h^2.
Fields smoothedCurvatures(const Input& in, Fields fields, double t) {
  HeatFlowParameters heat;
  heat.diffusion_time = t * in.h * in.h;
  const Eigen::MatrixXd four = rowsNamed(fields, kCurvatureNames);
  return {kCurvatureNames,
          smoothScalarFields(*in.topology, in.positions(), four.transpose(), heat).transpose()};
}

// -color field -percentile p: the diverging map clamped at the p-th and (100 - p)-th percentiles.
Fields colours(const Fields& fields, const std::string& name, double percentile) {
  const Eigen::VectorXd values = rowsNamed(fields, {name}).row(0).transpose();
  return {{"red", "green", "blue"},
          colorize(values, ColorMap::Diverging, {percentile, 100.0 - percentile}).cast<double>()};
}

TEST_F(ToolOptions, CurvatureEqualsTheLibraryForEveryAreaFitSmoothingAndColour) {
  const std::string file = sharedData("meshes/bunny.off");
  const Input in = readInput(file);
  const auto cotan = [&](MassType m) { return [&in, m] { return cotanCurvatures(in, m); }; };
  const auto quadric = [&](LocalFitOptions o) {
    return [&in, o] { return quadricCurvatures(in, o); };
  };
  const auto mixed = once(cotan(MassType::MixedVoronoi));
  const auto barycentric = once(cotan(MassType::Barycentric));
  const auto smoothed = [&](double t) {
    return once([&in, mixed, t] { return smoothedCurvatures(in, mixed(), t); });
  };
  const auto coloured = [&](std::string name, double p) {
    return once([mixed, name, p] { return colours(mixed(), name, p); });
  };
  using K = NeighbourhoodKind;
  const auto fit = [](K kind, int k) { return meshFit(LocalFitMethod::Quadric, kind, k); };
  const double h = in.h;
  const auto quadric20 = once(quadric(fit(K::MeshRings, 20)));
  const auto ball = once(quadric(withRadius(fit(K::MeshRings, 20), 2.5 * h)));
  const auto smooth1 = smoothed(1.0);
  const auto mean_colours = coloured("mean_curvature", 2.0), k1_colours = coloured("k1", 2.0);
  const std::vector<OptionCase> table = {
      {"", mixed, {}},
      {"-method cotan -area mixed", mixed, barycentric},  // the default: the row above pins it
      {"-area voronoi", cotan(MassType::Voronoi), mixed},
      {"-area barycentric", barycentric, mixed},
      {"-method quadric", quadric20, mixed},
      {"-method quadric -k 30", quadric(fit(K::MeshRings, 30)), quadric20},
      {"-method quadric -neighbours kdtree", quadric(fit(K::KdTree, 20)), quadric20},
      {"-method quadric -radius 2.5h", ball, quadric20},
      {"-method quadric -radius 2.5h -max_nn 12",
       quadric(withRadius(fit(K::MeshRings, 20), 2.5 * h, 12)), ball},
      {"-smooth 1", smooth1, mixed},
      {"-smooth 3", smoothed(3.0), smooth1},
      // Colours are bytes: equal or not. -color picks the field, -percentile the clamp.
      {"-color mean", mean_colours, {}},
      {"-color gauss", coloured("gauss_curvature", 2.0), mean_colours},
      {"-color k1", k1_colours, mean_colours},
      {"-color k2", coloured("k2", 2.0), k1_colours},
      {"-color mean -percentile 10", coloured("mean_curvature", 10.0), mean_colours},
      {"-color mean -percentile 0", coloured("mean_curvature", 0.0), mean_colours},
  };
  checkOptionTable(PCL_DDG_CURVATURE_TOOL, file, path("k.ply"), "-precision double", Match::Exact,
                   table);
}

// ---------------------------------------------------------------------------------------------
// pcl_ddg_smooth

// The tool's time step: -lambda_dt (Taubin: -lambda, and -mu) in h^2 when averaged by area
// (length^2 with -absolute_time), without unit when averaged by degree; the flow's explicit
// default: half the stability bound; Taubin's: 0.5 and -0.53.
Fields smoothedMesh(const Input& in, MeshSmoothingParameters p, std::optional<double> lambda_dt,
                    bool absolute_time = false) {
  const double unit = p.average == FlowAverage::Area && !absolute_time ? in.h * in.h : 1.0;
  p.taubin_mu *= unit;
  if (p.scheme == SmoothingScheme::Taubin) {
    p.time_step = lambda_dt.value_or(0.5) * unit;
  } else if (!lambda_dt) {
    p.time_step = p.scheme == SmoothingScheme::Explicit
                      ? 0.5 * explicitStabilityLimit(*in.topology, in.positions(), p.weights,
                                                     p.mass, p.average)
                      : unit;
  } else {
    p.time_step = *lambda_dt * unit;
  }
  return {{"x", "y", "z"}, smoothMeshPositions(*in.topology, in.positions(), p)};
}

TEST_F(ToolOptions, SmoothEqualsTheLibraryForEveryScheme) {
  const std::string cow_file = sharedData("meshes/cow.off");
  const std::string open_file = sharedData("meshes/bun_zipper_res4.ply");  // 26 boundary edges
  const Input cow = readInput(cow_file), open = readInput(open_file);
  using P = MeshSmoothingParameters;
  const auto on = [](const Input& in, P p, std::optional<double> dt = {}, bool absolute = false) {
    return once([&in, p, dt, absolute] { return smoothedMesh(in, p, dt, absolute); });
  };
  // The settings, each one change from the library's defaults (which are the tool's).
  const P implicit;
  P explicit_scheme, explicit5, uniform, voronoi, barycentric, explicit_barycentric, three,
      mass_follows, rebuilt, volume, area, fixed, umbrella, umbrella5, degree, taubin, taubin5,
      explicit_cotan, explicit_cotan5, no_limit, limit2, explicit_cotan_tight;
  explicit_cotan.scheme = explicit_cotan5.scheme = explicit_barycentric.scheme =
      SmoothingScheme::Explicit;
  explicit_cotan5.iterations = 5;
  // Explicit and Taubin default to the umbrella operator: uniform weights averaged by degree.
  for (P* p : {&explicit_scheme, &explicit5, &umbrella, &umbrella5, &taubin, &taubin5}) {
    p->weights = LaplacianWeights::Uniform;
    p->average = FlowAverage::Degree;
  }
  explicit_scheme.scheme = explicit5.scheme = SmoothingScheme::Explicit;
  explicit5.iterations = umbrella5.iterations = 5;
  degree.average = FlowAverage::Degree;
  taubin.scheme = taubin5.scheme = SmoothingScheme::Taubin;
  taubin5.iterations = 5;
  P taubin5_default_mu = taubin5;
  taubin5.taubin_mu = -0.45;
  uniform.weights = LaplacianWeights::Uniform;
  voronoi.mass = MassType::Voronoi;
  barycentric.mass = explicit_barycentric.mass = MassType::Barycentric;
  three.iterations = mass_follows.iterations = rebuilt.iterations = 3;
  mass_follows.weight_update = WeightUpdate::FrozenStiffness;
  rebuilt.weight_update = WeightUpdate::EveryIteration;
  volume.shrinkage = ShrinkageCorrection::PreserveVolume;
  area.shrinkage = ShrinkageCorrection::PreserveArea;
  fixed.boundary = BoundaryCondition::Fixed;
  // The thickness limit's value as the library takes it (its meaning: test_thickness_limit).
  no_limit.thickness_limit = 0.0;
  explicit_cotan_tight.thickness_limit = 0.01;  // the explicit step is short: a tight limit
  limit2.thickness_limit = 2.0;
  explicit_cotan_tight.scheme = SmoothingScheme::Explicit;
  const auto cow_default = on(cow, implicit), cow_three = on(cow, three);
  std::printf("cow.off: h^2 = %.3g\n", cow.h * cow.h);
  const std::vector<OptionCase> table = {
      {"", cow_default, {}},
      {"-method explicit", on(cow, explicit_scheme), cow_default},
      {"-method explicit -lambda_dt 0.3 -iterations 5", on(cow, explicit5, 0.3),
       on(cow, explicit5)},
      {"-method explicit -weights cotan", on(cow, explicit_cotan), on(cow, explicit_scheme)},
      {"-method explicit -weights cotan -lambda_dt 4e-4 -iterations 5",
       on(cow, explicit_cotan5, 4e-4), on(cow, explicit_cotan5)},
      {"-method explicit -weights umbrella", on(cow, explicit_scheme), on(cow, explicit_cotan)},
      {"-weights umbrella", on(cow, umbrella), on(cow, uniform)},
      {"-weights uniform -average degree -iterations 5", on(cow, umbrella5), on(cow, umbrella)},
      {"-average degree", on(cow, degree), cow_default},
      {"-method taubin", on(cow, taubin), on(cow, explicit_scheme)},
      {"-method taubin -lambda 0.4 -mu -0.45 -iterations 5", on(cow, taubin5, 0.4),
       on(cow, taubin5_default_mu, 0.4)},
      {"-weights uniform", on(cow, uniform), cow_default},
      {"-weights cotan", cow_default, on(cow, uniform)},  // the default: the first row pins it
      {"-area voronoi", on(cow, voronoi), cow_default},
      {"-mass voronoi", on(cow, voronoi), cow_default},  // the former name
      {"-area barycentric", on(cow, barycentric), cow_default},
      // The explicit default step is half the stability bound of the chosen mass.
      {"-method explicit -weights cotan -area barycentric", on(cow, explicit_barycentric),
       on(cow, explicit_cotan)},
      {"-lambda_dt 3", on(cow, implicit, 3.0), cow_default},
      {"-iterations 3", cow_three, cow_default},
      // 1e-5 in length^2 is about 0.02 h^2 on the cow; read in h^2 it would be 5e-9 length^2.
      {"-lambda_dt 1e-5 -absolute_time", on(cow, implicit, 1e-5, true), on(cow, implicit, 1e-5)},
      // One step sees only the input's operator: the weight updates differ from the second on.
      {"-iterations 3 -update_mass", on(cow, mass_follows), cow_three},
      {"-iterations 3 -freeze_weights", cow_three, on(cow, mass_follows)},  // names the default
      {"-iterations 3 -rebuild_weights", on(cow, rebuilt), cow_three},
      {"-preserve volume", on(cow, volume), cow_default},
      {"-preserve area", on(cow, area), cow_default},
      {"-thickness_limit 0", on(cow, no_limit), cow_default},
      {"-thickness_limit 2", on(cow, limit2), cow_default},
      {"-method explicit -weights cotan -thickness_limit 0.01", on(cow, explicit_cotan_tight),
       on(cow, explicit_cotan)},
      {"", on(open, implicit), {}, open_file},
      {"-fix_boundary", on(open, fixed), on(open, implicit), open_file},
  };
  checkOptionTable(PCL_DDG_SMOOTH_TOOL, cow_file, path("s.ply"), "-precision double", Match::Exact,
                   table);
}

// ---------------------------------------------------------------------------------------------
// pcl_ddg_smooth_organized and pcl_ddg_compare_neighbourhoods on a frame

// A small organized frame (40 x 30, ASCII PCD) seen from its VIEWPOINT (0.1, -0.05, 0): a wavy
// wall 2 m away whose right half stands 0.3 m (15 %) farther back, with a few holes. The step
// separates the default depth-jump thresholds (0.05 and 0.02) from 0.5.
void writeFrame(const std::string& path) {
  const int width = 40, height = 30;
  const Eigen::Vector3d origin(0.1, -0.05, 0.0);
  std::ostringstream text;
  text << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " << width
       << "\nHEIGHT " << height << "\nVIEWPOINT 0.1 -0.05 0 1 0 0 0\nPOINTS " << width * height
       << "\nDATA ascii\n";
  char line[96];
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if ((7 * u + 3 * v) % 23 == 0) {
        text << "nan nan nan\n";
        continue;
      }
      const Eigen::Vector3d ray =
          Eigen::Vector3d(0.02 * (u - 19.5), 0.02 * (v - 14.5), 1.0).normalized();
      const double range = 2.0 + (u >= width / 2 ? 0.3 : 0.0) +
                           0.02 * std::sin(0.7 * u) * std::cos(0.5 * v) +
                           0.004 * (((u * 37 + v * 11) % 17) / 16.0 - 0.5);
      const Eigen::Vector3d p = origin + range * ray;
      std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", p.x(), p.y(), p.z());
      text << line;
    }
  }
  writeText(path, text.str());
}

Fields smoothedFrame(const Input& in, const GridSmoothingParameters& p) {
  return {
      {"x", "y", "z"},
      smoothOrganizedPositions(in.positions(), static_cast<int>(in.points->width),
                               static_cast<int>(in.points->height), in.file.sensor_pose.origin, p)};
}

TEST_F(ToolOptions, SmoothOrganizedEqualsTheLibraryForEveryOption) {
  writeFrame(path("frame.pcd"));
  const Input in = readInput(path("frame.pcd"));
  ASSERT_EQ(in.points->height, 30u);
  using P = GridSmoothingParameters;
  const auto with = [](std::function<void(P&)> set) {
    P p;
    set(p);
    return p;
  };
  const auto on = [&in](P p) { return [&in, p] { return smoothedFrame(in, p); }; };
  const P implicit;
  const P explicit_scheme = with([](P& p) {
    p.scheme = SmoothingScheme::Explicit;
    p.time_step = 0.2;
  });
  const std::vector<OptionCase> table = {
      {"", on(implicit), {}},
      {"-method explicit", on(explicit_scheme), on(implicit)},
      {"-method explicit -lambda_dt 0.1", on(with([](P& p) {
         p.scheme = SmoothingScheme::Explicit;
         p.time_step = 0.1;
       })),
       on(explicit_scheme)},
      {"-lambda_dt 4", on(with([](P& p) { p.time_step = 4.0; })), on(implicit)},
      {"-iterations 3", on(with([](P& p) { p.iterations = 3; })), on(implicit)},
      {"-max_depth_jump 0.5", on(with([](P& p) { p.max_depth_jump = 0.5; })), on(implicit)},
  };
  // The tool writes float coordinates (no -precision option).
  checkOptionTable(PCL_DDG_SMOOTH_ORGANIZED_TOOL, path("frame.pcd"), path("s.pcd"), "",
                   Match::FloatRounding, table);
}

// angle_difference, overlap, and the colours of -color (default angle_difference, clamped at 30
// degrees; overlap as it is), on the sequential map over the whole range.
Fields comparison(const Input& in, LocalFitOptions options, const std::string& color) {
  const NeighbourhoodComparison c = compareNeighbourhoods(in.local, in.topology, options);
  const Eigen::VectorXd coloured =
      color == "overlap" ? c.overlap : Eigen::VectorXd(c.angle_difference.cwiseMin(30.0));
  Fields f{{"angle_difference", "overlap", "red", "green", "blue"},
           Eigen::MatrixXd(5, c.overlap.size())};
  f.values.row(0) = c.angle_difference.transpose();
  f.values.row(1) = c.overlap.transpose();
  f.values.bottomRows(3) = colorize(coloured, ColorMap::Sequential, {0.0, 100.0}).cast<double>();
  return f;
}

TEST_F(ToolOptions, CompareNeighbourhoodsEqualsTheLibraryForEveryOption) {
  const std::string file = sharedData("meshes/bumpy.off");
  const Input in = readInput(file);
  writeFrame(path("frame.pcd"));
  const Input frame = readInput(path("frame.pcd"));
  // k is 16 for both methods unless -k says otherwise; the viewpoint is the file's.
  const auto fit = [](const Input& input, LocalFitMethod method, int k) {
    LocalFitOptions o = meshFit(method, NeighbourhoodKind::KdTree, k);
    o.viewpoint = input.file.sensor_pose.origin;
    return o;
  };
  const auto on = [](const Input& input, LocalFitOptions o, std::string color = "") {
    return once([&input, o, color] { return comparison(input, o, color); });
  };
  const LocalFitMethod pca = LocalFitMethod::PCA;
  const double h = in.h;
  LocalFitOptions jump = fit(frame, pca, 16);
  jump.max_depth_jump = 0.5;
  const auto pca16 = on(in, fit(in, pca, 16)), overlap = on(in, fit(in, pca, 16), "overlap");
  const auto ball = on(in, withRadius(fit(in, pca, 16), 2.5 * h));
  const auto frame16 = on(frame, fit(frame, pca, 16));
  const std::vector<OptionCase> table = {
      {"", pca16, {}},
      {"-k 8", on(in, fit(in, pca, 8)), pca16},
      {"-method quadric", on(in, fit(in, LocalFitMethod::Quadric, 16)), pca16},
      {"-radius 2.5h", ball, pca16},
      {"-radius 2.5h -max_nn 8", on(in, withRadius(fit(in, pca, 16), 2.5 * h, 8)), ball},
      {"-color overlap", overlap, pca16},
      {"-color angle_difference", pca16, overlap},  // the default: the first row pins it
      {"", frame16, {}, path("frame.pcd")},
      {"-max_depth_jump 0.5", on(frame, jump), frame16, path("frame.pcd")},
  };
  checkOptionTable(PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL, file, path("c.ply"), "-precision double",
                   Match::Exact, table);
  // -color none: the two fields and no colours.
  ASSERT_EQ(
      runTool(PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL, file + " " + path("none.ply") + " -color none")
          .exit_code,
      0);
  const pcl::PolygonMesh none = loadMesh(path("none.ply"));
  EXPECT_TRUE(hasVertexField(none.cloud, "angle_difference"));
  EXPECT_FALSE(hasVertexField(none.cloud, "red"));
}

// ---------------------------------------------------------------------------------------------
// pcl_ddg_render

std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// One picture option: the tool's PNG must be the library's picture with that camera and colour
// setting, and that picture must differ from the one without the option.
struct RenderCase {
  std::string options;
  std::function<Image()> library;
  std::function<Image()> without_option;
};

TEST_F(ToolOptions, RenderEqualsTheLibraryForEveryCameraAndColourOption) {
  // The cow with a signed field (height above its mean), so both colour maps have work to do.
  {
    pcl::PolygonMesh cow = loadMesh(sharedData("meshes/cow.off"));
    const Eigen::VectorXd y = vertexScalarField(cow.cloud, "y");
    setVertexField(cow.cloud, "height", (y.array() - y.mean()).matrix());
    saveMesh(path("cow.ply"), cow);
  }
  const MeshFile file = readMeshFile(path("cow.ply"));
  const MeshTopology topology(file.mesh, OutOfRangeFacePolicy::Drop);
  // Without -up the view that shows the most of the cow (defaultView, its faces' side); with a
  // field, the colour bar beside the picture.
  const DefaultView shown =
      defaultView(file.positions, meshOrientationNormals(topology, file.positions), false);
  const auto picture = [&](std::function<void(RenderOptions&)> set, std::string field = "",
                           ColorMap map = ColorMap::Diverging) {
    return [&, set, field, map] {
      RenderOptions o;
      o.width = o.height = 96;
      o.front = shown.front;
      o.up = shown.up;
      set(o);
      VertexColors colors(3, file.positions.cols());
      colors.setConstant(215);  // no field, no colours of its own: light grey
      if (field.empty()) return renderMesh(file.positions, topology.triangles(), colors, o);
      const Eigen::VectorXd values = vertexScalarField(file.mesh.cloud, field);
      return withColorBar(
          renderMesh(file.positions, topology.triangles(), colorize(values, map), o), map,
          colorRange(values, map), field);
    };
  };
  const auto up = [](const Eigen::Vector3d& axis) {
    return [axis](RenderOptions& o) {
      o.up = axis;
      o.front.setZero();  // -up: from the fixed side
    };
  };
  const auto camera = [](RenderOptions&) {};
  const std::vector<RenderCase> table = {
      {"", picture([](RenderOptions& o) { o.width = o.height = 800; }), {}},
      {"-size 96", picture(camera), picture([](RenderOptions& o) { o.width = o.height = 800; })},
      {"-size 64", picture([](RenderOptions& o) { o.width = o.height = 64; }), picture(camera)},
      {"-size 96 -azimuth 90", picture([](RenderOptions& o) { o.azimuth_degrees = 90; }),
       picture(camera)},
      {"-size 96 -azimuth 0", picture([](RenderOptions& o) { o.azimuth_degrees = 0; }),
       picture([](RenderOptions& o) { o.azimuth_degrees = 90; })},
      {"-size 96 -elevation 60", picture([](RenderOptions& o) { o.elevation_degrees = 60; }),
       picture(camera)},
      {"-size 96 -up z", picture(up(Eigen::Vector3d::UnitZ())), picture(camera)},
      {"-size 96 -up x", picture(up(Eigen::Vector3d::UnitX())), picture(camera)},
      // (On the cow, y up from the fixed side is nearly its default view: compared with x.)
      {"-size 96 -up y", picture(up(Eigen::Vector3d::UnitY())),
       picture(up(Eigen::Vector3d::UnitX()))},
      {"-size 96 -up -y", picture(up(-Eigen::Vector3d::UnitY())),
       picture(up(Eigen::Vector3d::UnitY()))},
      {"-size 96 -up -z", picture(up(-Eigen::Vector3d::UnitZ())),
       picture(up(Eigen::Vector3d::UnitZ()))},
      {"-size 96 -field height", picture(camera, "height"), picture(camera)},
      {"-size 96 -field height -map sequential", picture(camera, "height", ColorMap::Sequential),
       picture(camera, "height")},
      {"-size 96 -field height -map diverging", picture(camera, "height"),
       picture(camera, "height", ColorMap::Sequential)},
  };
  for (const RenderCase& row : table) {
    SCOPED_TRACE("pcl_ddg_render " + row.options);
    std::filesystem::remove(path("tool.png"));
    const ToolRun run =
        runTool(PCL_DDG_RENDER_TOOL, path("cow.ply") + " " + path("tool.png") + " " + row.options);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const Image expected = row.library();
    savePNG(path("library.png"), expected);
    // The same pixels make the same PNG (one encoder): byte equality is pixel equality.
    EXPECT_TRUE(fileBytes(path("tool.png")) == fileBytes(path("library.png")))
        << "the tool's picture is not the library's with this setting";
    if (!row.without_option) continue;
    const Image other = row.without_option();
    if (other.width != expected.width || other.height != expected.height) continue;
    std::int64_t changed = 0;
    for (std::size_t i = 0; i < expected.rgb.size(); i += 3) {
      changed += !std::equal(expected.rgb.begin() + i, expected.rgb.begin() + i + 3,
                             other.rgb.begin() + i);
    }
    std::printf("pcl_ddg_render %s: %lld of %d pixels differ from the default's\n",
                row.options.c_str(), static_cast<long long>(changed),
                expected.width * expected.height);
    // A camera or colour change repaints much of the cow, not a few edge pixels.
    EXPECT_GT(changed, expected.width * expected.height / 20);
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
