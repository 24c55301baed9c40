// Point cloud functions: fitted normals and curvatures (pca, quadric, robust) with kd-tree,
// mesh-ring or pixel-grid neighbourhoods, orientation, and the neighbourhood comparison. The points
// are placed about their local origin as the tools place a file's (local_cloud.h), so results equal
// the tools'.
#include <pcl/exceptions.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "binding_common.h"
#include "pcl_ddg/features/consistent_orientation.h"
#include "pcl_ddg/features/fit_choices.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/features/neighbourhood_comparison.h"
#include "pcl_ddg/features/robust_normal_estimation.h"
#include "pcl_ddg/result_warnings.h"

namespace pcl_ddg {
namespace python {

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

template <typename T>
bool readPoints(const py::array& array, Eigen::Matrix3Xd& positions, std::size_t width) {
  const py::dtype dtype = py::dtype::of<T>();
  if (dtype.kind() != array.dtype().kind() || dtype.itemsize() != array.dtype().itemsize())
    return false;
  const auto* base = static_cast<const char*>(array.data());
  const int nd = static_cast<int>(array.ndim());
  const py::ssize_t s_row = array.strides(nd == 3 ? 1 : 0), s_coord = array.strides(nd - 1);
  const py::ssize_t s_grid = nd == 3 ? array.strides(0) : 0;
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    const char* row = base + static_cast<py::ssize_t>(i / width) * s_grid +
                      static_cast<py::ssize_t>(i % width) * s_row;
    // In double, as the tools read a file (exact for every type but 64-bit integers).
    for (int d = 0; d < 3; ++d)
      positions(d, i) = static_cast<double>(*reinterpret_cast<const T*>(row + d * s_coord));
  }
  return true;
}

// (n, 3) or organized (h, w, 3) points about their local origin, as the tools place a file's
// (local_cloud.h): float64 coordinates are fitted as they are, wherever they lie.
LocalCloud cloudOf(const py::array& points) {
  const int nd = static_cast<int>(points.ndim());
  if ((nd != 2 && nd != 3) || points.shape(nd - 1) != 3)
    throw py::value_error("points must have shape (n, 3) or (h, w, 3)");
  const char kind = points.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::value_error("points must hold real numbers, not " +
                          std::string(py::str(points.dtype())));
  if (points.size() / 3 > std::numeric_limits<int>::max())
    throw py::value_error("points has more rows than the library indexes");
  const auto width = static_cast<std::uint32_t>(nd == 3 ? points.shape(1) : points.shape(0));
  Eigen::Matrix3Xd positions(3, points.size() / 3);
  if (positions.cols() == 0) throw py::value_error("points is empty");
  py::array source = points;
  if (points.dtype().byteorder() == '>')
    source = py::array_t<double, py::array::forcecast>::ensure(points);
  if (!(readPoints<double>(source, positions, width) ||
        readPoints<float>(source, positions, width) ||
        readPoints<std::int64_t>(source, positions, width) ||
        readPoints<std::int32_t>(source, positions, width) ||
        readPoints<std::uint64_t>(source, positions, width) ||
        readPoints<std::uint32_t>(source, positions, width) ||
        readPoints<std::int16_t>(source, positions, width) ||
        readPoints<std::uint16_t>(source, positions, width) ||
        readPoints<std::int8_t>(source, positions, width) ||
        readPoints<std::uint8_t>(source, positions, width))) {
    const auto converted = py::array_t<double, py::array::forcecast>::ensure(points);
    readPoints<double>(converted, positions, width);
  }
  return makeLocalCloud(positions, nd == 3 ? width : 0);
}

std::optional<Eigen::Vector3d> vectorOf(const std::optional<std::vector<double>>& v,
                                        const char* name) {
  if (!v) return std::nullopt;
  if (v->size() != 3) throw py::value_error(std::string(name) + " must be three numbers x, y, z");
  const Eigen::Vector3d out(v->data());
  if (!out.allFinite()) throw py::value_error(std::string(name) + " must be finite");
  return out;
}

std::optional<Eigen::Vector3d> directionOf(const std::optional<std::vector<double>>& v) {
  std::optional<Eigen::Vector3d> up = vectorOf(v, "up");
  if (up && !(up->norm() > 0.0)) throw py::value_error("up needs a non-zero direction");
  if (up) up->normalize();
  return up;
}

// The output's shape: (n, c) for an (n, 3) input, (h, w, c) for a grid; c = 0 for (n,) / (h, w).
std::vector<py::ssize_t> shapeOf(const Cloud& cloud, py::ssize_t columns) {
  std::vector<py::ssize_t> shape;
  if (cloud.height > 1) {
    shape = {static_cast<py::ssize_t>(cloud.height), static_cast<py::ssize_t>(cloud.width)};
  } else {
    shape = {static_cast<py::ssize_t>(cloud.size())};
  }
  if (columns > 0) shape.push_back(columns);
  return shape;
}

py::array_t<double> normalsArray(const Cloud& cloud, const pcl::PointCloud<pcl::Normal>& normals) {
  py::array_t<double> out(shapeOf(cloud, 3));
  double* data = out.mutable_data();
  for (std::size_t i = 0; i < normals.size(); ++i) {
    for (int d = 0; d < 3; ++d) data[3 * i + d] = static_cast<double>(normals[i].normal[d]);
  }
  return out;
}

struct FitArguments {
  std::string method = "pca";
  std::optional<int> k;
  std::optional<double> radius;
  std::optional<int> max_nn, min_nn;
  std::optional<std::string> neighbours;
  py::object faces = py::none();
  std::optional<std::vector<double>> viewpoint;
  std::optional<std::string> orient;
  std::optional<std::vector<double>> up;
  std::optional<double> max_depth_jump;
  unsigned int threads = 0;
};

// The options of pcl_ddg_normals' in-memory path (localFitArguments), checked the same way.
LocalFitOptions fitOptions(const FitArguments& a, const Cloud& cloud,
                           std::shared_ptr<const MeshTopology>& topology) {
  FitRequest request;
  request.k = a.k;
  request.max_nn = a.max_nn;
  request.min_nn = a.min_nn;
  request.radius = a.radius;
  request.max_depth_jump = a.max_depth_jump;
  request.orient = a.orient;
  request.viewpoint = a.viewpoint.has_value();
  request.up = a.up.has_value();
  checkFitRequest(request, kPythonStyle);
  LocalFitOptions options;
  options.method = chooseFitMethod(a.method, kPythonStyle);
  if (!a.faces.is_none()) {
    if (cloud.height > 1) throw py::value_error("faces need points of shape (n, 3)");
    for (const pcl::PointXYZ& p : cloud) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw py::value_error("a mesh's vertices must be finite (faces were given)");
    }
    topology =
        std::make_shared<const MeshTopology>(topologyOf(static_cast<int>(cloud.size()), a.faces));
  }
  const bool organized = !topology && cloud.height > 1;
  options.neighbourhood =
      chooseNeighbourhood(a.neighbours, topology != nullptr, organized, kPythonStyle);
  if (a.max_depth_jump && options.neighbourhood != NeighbourhoodKind::Grid)
    throw py::value_error("max_depth_jump applies to neighbours='grid'");
  if (a.max_depth_jump) options.max_depth_jump = *a.max_depth_jump;
  applyNeighbourCounts(request, static_cast<std::int64_t>(cloud.size()), kPythonStyle, options);
  if (a.orient) {
    options.orientation = chooseOrientation(*a.orient, kPythonStyle);
    checkOrientationInput(options.orientation, topology != nullptr, kPythonStyle);
  }
  // As the tool: the viewpoint is the sensor's (a PCD's VIEWPOINT), the origin by default.
  options.viewpoint = vectorOf(a.viewpoint, "viewpoint").value_or(Eigen::Vector3d::Zero());
  options.up = directionOf(a.up);
  options.seed_facing_viewpoint = !a.up && (a.viewpoint || cloud.height > 1);
  options.threads = a.threads;
  return options;
}

// What pcl_ddg_normals warns about this fit (fit_warnings.h), with the options spelled as
// Python's: the sampling of a cloud (a mesh's faces orient it, its edges are its spacing), and
// the points left without an estimate.
std::vector<std::string> fitWarnings(const LocalCloud& local, bool mesh,
                                     const LocalFitOptions& options, const LocalFitResult& result) {
  std::vector<std::string> messages;
  if (!mesh) {
    if (auto message = quantisationWarning(measurePointSpacing(*local.points)))
      messages.push_back(std::move(*message));
    Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d max = -min;
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(local.points->size()); ++i) {
      const Eigen::Vector3d p = local.positions
                                    ? Eigen::Vector3d(local.positions->col(i))
                                    : (*local.points)[i].getVector3fMap().cast<double>();
      if (!p.allFinite()) continue;
      min = min.cwiseMin(p);
      max = max.cwiseMax(p);
    }
    if (auto message = farViewpointWarning(min + local.origin, max + local.origin, options, {}))
      messages.push_back(std::move(*message));
  }
  for (std::string& message : fitResultWarnings(result.failed_points, result.fallback_points))
    messages.push_back(std::move(message));
  return messages;
}

py::dict fitCounts(const LocalFitResult& result, const std::vector<std::string>& warnings) {
  py::dict counts;
  counts["failed_points"] = result.failed_points;
  counts["fallback_points"] = result.fallback_points;
  counts["flipped_points"] = result.orientation.flipped_points;
  counts["warnings"] = warnings;
  return counts;
}

}  // namespace

void bindClouds(py::module_& m) {
  const auto fit = [](const py::array& points, const FitArguments& arguments, bool curvatures) {
    const LocalCloud local = cloudOf(points);
    const Cloud::ConstPtr& cloud = local.points;
    std::shared_ptr<const MeshTopology> topology;
    const LocalFitOptions options = fitOptions(arguments, *cloud, topology);
    std::vector<std::string> warnings;
    const LocalFitResult result = compute([&] {
      LocalFitResult fitted = fitLocalSurfaces(local, topology, options);
      warnings = fitWarnings(local, topology != nullptr, options, fitted);
      return fitted;
    });
    py::array_t<double> normals = normalsArray(*cloud, result.normals);
    py::array_t<bool> valid(shapeOf(*cloud, 0));
    bool* ok = valid.mutable_data();
    const double* n = normals.data();
    for (std::size_t i = 0; i < cloud->size(); ++i)
      ok[i] = std::isfinite(n[3 * i]) && std::isfinite(n[3 * i + 1]) && std::isfinite(n[3 * i + 2]);
    if (!curvatures) {
      py::array_t<double> curvature(shapeOf(*cloud, 0));
      double* c = curvature.mutable_data();
      for (std::size_t i = 0; i < cloud->size(); ++i) c[i] = result.normals[i].curvature;
      if (result.scales.empty())
        return py::make_tuple(normals, curvature, valid, fitCounts(result, warnings), py::none(),
                              py::none());
      py::array_t<double> scale(shapeOf(*cloud, 0)), confidence(shapeOf(*cloud, 0));
      std::copy(result.scales.begin(), result.scales.end(), scale.mutable_data());
      std::copy(result.confidences.begin(), result.confidences.end(), confidence.mutable_data());
      return py::make_tuple(normals, curvature, valid, fitCounts(result, warnings), scale,
                            confidence);
    }
    py::array_t<double> k1(shapeOf(*cloud, 0)), k2(shapeOf(*cloud, 0));
    py::array_t<double> direction(shapeOf(*cloud, 3));
    double *pc1 = k1.mutable_data(), *pc2 = k2.mutable_data(), *dir = direction.mutable_data();
    for (std::size_t i = 0; i < cloud->size(); ++i) {
      const pcl::PrincipalCurvatures& p = result.curvatures[i];
      pc1[i] = p.pc1;
      pc2[i] = p.pc2;
      dir[3 * i] = p.principal_curvature_x;
      dir[3 * i + 1] = p.principal_curvature_y;
      dir[3 * i + 2] = p.principal_curvature_z;
      ok[i] = ok[i] && std::isfinite(pc1[i]) && std::isfinite(pc2[i]);
    }
    return py::make_tuple(k1, k2, direction, normals, valid, fitCounts(result, warnings));
  };

  m.def(
      "estimate_normals",
      [fit](const py::array& points, const std::string& method, std::optional<int> k,
            std::optional<double> radius, std::optional<int> max_nn, std::optional<int> min_nn,
            std::optional<std::string> neighbours, const py::object& faces,
            std::optional<std::vector<double>> viewpoint, std::optional<std::string> orient,
            std::optional<std::vector<double>> up, std::optional<double> max_depth_jump,
            unsigned int threads) {
        return fit(points,
                   {method, k, radius, max_nn, min_nn, neighbours, faces, viewpoint, orient, up,
                    max_depth_jump, threads},
                   false);
      },
      py::arg("points"), py::arg("method") = "pca", py::arg("k") = py::none(),
      py::arg("radius") = py::none(), py::arg("max_nn") = py::none(),
      py::arg("min_nn") = py::none(), py::arg("neighbours") = py::none(),
      py::arg("faces") = py::none(), py::arg("viewpoint") = py::none(),
      py::arg("orient") = py::none(), py::arg("up") = py::none(),
      py::arg("max_depth_jump") = py::none(), py::arg("threads") = 0,
      "(normals, curvature, valid, counts, scale, confidence) of fitLocalSurfaces, as "
      "pcl_ddg_normals (scale and confidence: robust's, else None).");

  m.def(
      "principal_curvatures",
      [fit](const py::array& points, std::optional<int> k, std::optional<double> radius,
            std::optional<int> max_nn, std::optional<int> min_nn,
            std::optional<std::string> neighbours, const py::object& faces,
            std::optional<std::vector<double>> viewpoint, std::optional<std::string> orient,
            std::optional<std::vector<double>> up, unsigned int threads) {
        return fit(points,
                   {"quadric", k, radius, max_nn, min_nn, neighbours, faces, viewpoint, orient, up,
                    std::nullopt, threads},
                   true);
      },
      py::arg("points"), py::arg("k") = py::none(), py::arg("radius") = py::none(),
      py::arg("max_nn") = py::none(), py::arg("min_nn") = py::none(),
      py::arg("neighbours") = py::none(), py::arg("faces") = py::none(),
      py::arg("viewpoint") = py::none(), py::arg("orient") = py::none(), py::arg("up") = py::none(),
      py::arg("threads") = 0,
      "(k1, k2, direction1, normals, valid, counts) of the quadric fit, as pcl_ddg_curvature.");

  m.def(
      "orient_normals",
      [](const py::array& points, const py::array& normals, const std::string& method,
         std::optional<std::vector<double>> viewpoint, std::optional<std::vector<double>> up, int k,
         const py::object& faces) {
        const std::string how = choice("method", method, {"mst", "viewpoint", "up"});
        const int n = rowCount(points, "points");
        if (rowCount(normals, "normals") != n)
          throw py::value_error("normals must have as many rows as points");
        if (k < 1) throw py::value_error("k must be at least 1");
        if (how != "mst" && (k != 10 || !faces.is_none()))
          throw py::value_error("k and faces apply to method='mst'");
        if (how == "viewpoint" && up) throw py::value_error("up applies to 'up' and 'mst'");
        if (how == "up" && viewpoint)
          throw py::value_error("viewpoint applies to 'viewpoint' and 'mst'");
        if (how == "mst" && up && viewpoint)
          throw py::value_error("method='mst' takes one reference: viewpoint or up");
        const Eigen::Matrix3Xd p = positionsOf(points, "points");
        Eigen::Matrix3Xd out = positionsOf(normals, "normals");
        const std::optional<Eigen::Vector3d> vp = vectorOf(viewpoint, "viewpoint");
        const std::optional<Eigen::Vector3d> u = directionOf(up);
        std::shared_ptr<const MeshTopology> topology;
        if (!faces.is_none()) topology = std::make_shared<const MeshTopology>(topologyOf(n, faces));
        std::int64_t flipped = compute([&] {
          std::int64_t turned = 0;
          if (how != "mst") {
            const Eigen::Vector3d direction = u.value_or(Eigen::Vector3d::UnitZ());
            const Eigen::Vector3d from = vp.value_or(Eigen::Vector3d::Zero());
            for (int i = 0; i < n; ++i) {
              const double side =
                  how == "up" ? out.col(i).dot(direction) : out.col(i).dot(from - p.col(i));
              if (side < 0.0) {
                out.col(i) = -out.col(i);
                ++turned;
              }
            }
            return turned;
          }
          // The library orients PCL's float normals; its decisions are applied to the doubles.
          pcl::PointCloud<pcl::PointXYZ> cloud;
          pcl::PointCloud<pcl::Normal> float_normals;
          cloud.resize(static_cast<std::size_t>(n));
          float_normals.resize(static_cast<std::size_t>(n));
          for (int i = 0; i < n; ++i) {
            cloud[i].getVector3fMap() = p.col(i).cast<float>();
            float_normals[i].getNormalVector3fMap() = out.col(i).cast<float>();
          }
          const pcl::PointCloud<pcl::Normal> before = float_normals;
          ConsistentOrientationOptions options;
          options.k = k;
          options.viewpoint = vp;
          options.up = u;
          if (topology) {
            orientNormalsConsistently(*topology, cloud, float_normals, options);
          } else {
            orientNormalsConsistently(cloud, float_normals, options);
          }
          for (int i = 0; i < n; ++i) {
            if (float_normals[i].normal_x != before[i].normal_x ||
                float_normals[i].normal_y != before[i].normal_y ||
                float_normals[i].normal_z != before[i].normal_z) {
              out.col(i) = -out.col(i);
              ++turned;
            }
          }
          return turned;
        });
        return py::make_tuple(rowsArray(std::move(out)), flipped);
      },
      py::arg("points"), py::arg("normals"), py::arg("method") = "mst",
      py::arg("viewpoint") = py::none(), py::arg("up") = py::none(), py::arg("k") = 10,
      py::arg("faces") = py::none(), "(normals, flipped) oriented as normal_orientation.h.");

  m.def(
      "compare_neighbourhoods",
      [](const py::array& V, const py::object& F, const std::string& method, std::optional<int> k,
         std::optional<double> radius, std::optional<int> max_nn, unsigned int threads) {
        if (F.is_none() && V.ndim() != 3)
          throw py::value_error(
              "compare_neighbourhoods needs faces, or an organized (h, w, 3) cloud");
        const LocalCloud local = cloudOf(V);
        std::shared_ptr<const MeshTopology> topology;
        FitArguments a;
        a.method = method;
        a.k = radius ? k : std::optional<int>(k.value_or(16));  // the tool's default, also quadric
        a.radius = radius;
        a.max_nn = max_nn;
        a.faces = F;
        a.threads = threads;
        const LocalFitOptions options = fitOptions(a, *local.points, topology);
        NeighbourhoodComparison c =
            compute([&] { return compareNeighbourhoods(local, topology, options); });
        const NeighbourhoodComparison::Summary& s = c.summary;
        py::dict summary;
        summary["compared"] = s.compared;
        summary["mean"] = s.mean;
        summary["median"] = s.median;
        summary["percentile95"] = s.percentile95;
        summary["max"] = s.max;
        summary["share_over_5"] = s.share_over_5;
        summary["share_over_30"] = s.share_over_30;
        summary["mean_overlap"] = s.mean_overlap;
        return py::make_tuple(vectorArray(std::move(c.angle_difference)),
                              vectorArray(std::move(c.overlap)), summary);
      },
      py::arg("V"), py::arg("F"), py::arg("method") = "pca", py::arg("k") = py::none(),
      py::arg("radius") = py::none(), py::arg("max_nn") = py::none(), py::arg("threads") = 0,
      "(angle_difference, overlap, summary) of compareNeighbourhoods.");
}

}  // namespace python
}  // namespace pcl_ddg
