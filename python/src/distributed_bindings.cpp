// The compiled half of pcl_ddg.distributed (a dask.distributed runner): what a worker needs to read
// its own points from a shared file by byte ranges, fit a tile's core points with the out-of-core
// path's certified-halo rule (src/tiling/tiled_local_fit.cpp), and what the client needs to write
// the merged output the way the tools write it (src/tiling/out_of_core_fit.cpp, step 5), so that
// a distributed run equals `pcl_ddg_normals` / `pcl_ddg_curvature` on the merged cloud byte for
// byte. Every function releases the GIL while it reads, fits or writes.
#include <fcntl.h>
#include <pcl/exceptions.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "binding_common.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/features/fit_choices.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/io/atomic_file.h"
#include "pcl_ddg/io/cloud_pieces.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/result_warnings.h"
#include "pcl_ddg/search/kd_tree_search.h"
#include "pcl_ddg/tiling/byte_size.h"
#include "pcl_ddg/tiling/tile_certificate.h"

namespace pcl_ddg {
namespace python {
namespace {

[[noreturn]] void failSystem(const std::string& what) {
  throw FileFormatException(what + ": " + std::strerror(errno));
}

py::dict cloudLayout(const std::string& path) {
  py::list fields;
  CloudFileLayout layout;
  pcl::PCLPointCloud2 empty;
  std::vector<std::pair<std::int64_t, std::int64_t>> chunks;
  {
    py::gil_scoped_release release;
    CloudPieceReader pieces(path);
    layout = pieces.layout();
    chunks = pieces.lazChunks();
    empty = pieces.read(0, std::min<std::int64_t>(1, layout.points)).cloud;
  }
  for (const auto& f : empty.fields)
    fields.append(py::make_tuple(f.name, static_cast<int>(f.datatype), f.count, f.offset));
  py::dict d;
  d["points"] = layout.points;
  d["header_bytes"] = layout.header_bytes;
  d["point_bytes"] = layout.point_bytes;
  d["width"] = layout.width;
  d["height"] = layout.height;
  const SensorPose& pose = layout.sensor_pose;
  d["viewpoint"] = py::make_tuple(pose.origin.x(), pose.origin.y(), pose.origin.z());
  d["orientation"] = py::make_tuple(pose.orientation.w(), pose.orientation.x(),
                                    pose.orientation.y(), pose.orientation.z());
  d["fields"] = fields;
  d["chunks"] = chunks.empty() ? py::object(py::none()) : py::cast(chunks);
  return d;
}

// Points [first, first + count) of a cloud file, exact (double; NaN rows stay): a chunk's bounds
// for the plan and the local origin.
py::array_t<double> readPositions(const std::string& path, std::int64_t first, std::int64_t count) {
  py::array_t<double> out(
      {static_cast<py::ssize_t>(std::max<std::int64_t>(count, 0)), py::ssize_t{3}});
  double* data = out.mutable_data();
  {
    py::gil_scoped_release release;
    CloudPieceReader pieces(path);
    const Eigen::Matrix3Xd positions = pieces.read(first, count).positions;
    std::copy(positions.data(), positions.data() + positions.size(), data);
  }
  return out;
}

// A chunk's points that a tile gathers, relative to the run's local origin (local_cloud.h): those
// whose floats lie inside the closed box [lo, hi] and (tile >= 0) the tile's own (their grid cell,
// half-open: floor((x - origin) / size), clamped to the grid). Returns (float32 points, the same
// in double, their positions in the chunk, own mask), in the chunk's order.
py::tuple gatherChunk(const std::string& path, std::int64_t first, std::int64_t count,
                      const std::vector<double>& lo, const std::vector<double>& hi,
                      const std::vector<double>& origin, const std::vector<double>& size,
                      const std::vector<std::int64_t>& dims, std::int64_t tile,
                      const std::vector<double>& local_origin) {
  if (lo.size() != 3 || hi.size() != 3 || origin.size() != 3 || size.size() != 3 ||
      dims.size() != 3 || local_origin.size() != 3)
    throw py::value_error("lo, hi, origin, size, dims and local_origin are x, y, z");
  std::vector<float> kept;
  std::vector<double> kept_exact;
  std::vector<std::int64_t> at;
  std::vector<std::uint8_t> own;
  {
    py::gil_scoped_release release;
    CloudPieceReader pieces(path);
    const Eigen::Matrix3Xd positions = pieces.read(first, count).positions;
    for (Eigen::Index i = 0; i < positions.cols(); ++i) {
      float f[3];
      double v[3], exact[3];
      bool finite = true, inside = true;
      for (int d = 0; d < 3; ++d) {
        exact[d] = positions(d, i) - local_origin[d];
        if (std::isfinite(exact[d]) && std::abs(exact[d]) > std::numeric_limits<float>::max())
          throw FileFormatException(path + ": a point lies beyond float's range from the others");
        f[d] = static_cast<float>(exact[d]);
        v[d] = static_cast<double>(f[d]);
        finite = finite && std::isfinite(v[d]);
        inside = inside && v[d] >= lo[d] && v[d] <= hi[d];
      }
      if (!finite) continue;
      bool mine = false;
      if (tile >= 0) {
        std::int64_t cell[3];
        for (int d = 0; d < 3; ++d) {
          const double c = std::floor((v[d] - origin[d]) / size[d]);
          cell[d] = static_cast<std::int64_t>(std::clamp(c, 0.0, static_cast<double>(dims[d] - 1)));
        }
        mine = (cell[0] * dims[1] + cell[1]) * dims[2] + cell[2] == tile;
      }
      if (!inside && !mine) continue;
      kept.insert(kept.end(), f, f + 3);
      kept_exact.insert(kept_exact.end(), exact, exact + 3);
      at.push_back(i);
      own.push_back(mine ? 1 : 0);
    }
  }
  py::array_t<float> points({static_cast<py::ssize_t>(at.size()), py::ssize_t{3}});
  if (!kept.empty()) std::memcpy(points.mutable_data(), kept.data(), kept.size() * sizeof(float));
  py::array_t<double> exact({static_cast<py::ssize_t>(at.size()), py::ssize_t{3}});
  std::copy(kept_exact.begin(), kept_exact.end(), exact.mutable_data());
  std::vector<std::uint8_t> own_copy = own;
  return py::make_tuple(points, exact, vectorArray(std::move(at)), maskArray(own_copy));
}

Eigen::AlignedBox3d boxOf(const std::vector<double>& b) {
  if (b.size() != 6) throw py::value_error("a box is (xmin, ymin, zmin, xmax, ymax, zmax)");
  return {Eigen::Vector3d(b[0], b[1], b[2]), Eigen::Vector3d(b[3], b[4], b[5])};
}

/**
 * Fits the `own` points of a gathered tile (points in the merged cloud's order, so that the
 * kd-tree's ties break as on the whole cloud). mode "certified": a point's fit counts only when
 * its look (lookingDistance, tile_certificate.h: its k-th neighbour among the gathered points,
 * and for robust the rows its wider planes read) is nearer than the halo box's edge (haloReach),
 * as the fit's own search finds it; the others
 * come back uncertified, with how far they looked, for a wider gather. "all": every own point is
 * fitted. Radius searches are certified by a halo of the radius, so the check applies to k only.
 * Returns (records (n_own, 4, 9 or 6) float32: nx ny nz curvature, then the quadric's pc1 pc2
 * k1 direction or robust's scale confidence,
 * certified, looking distance, reach (how far each point may look inside the halo box; infinity
 * unchecked), failed, fallback).
 */
py::tuple fitTile(const py::array_t<float, py::array::c_style | py::array::forcecast>& xyz,
                  const py::array_t<double, py::array::c_style | py::array::forcecast>& exact,
                  const std::vector<double>& local_origin,
                  const py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>& own,
                  const std::string& method, int k, double radius, unsigned int max_nn,
                  const std::vector<double>& viewpoint, const std::string& orient,
                  const std::optional<std::vector<double>>& up,
                  const std::optional<std::vector<double>>& halo_box,
                  const std::vector<double>& bounds, const std::string& mode, unsigned int threads,
                  std::int64_t cloud_points) {
  const bool certify = choice("mode", mode, {"certified", "all"}) == "certified";
  if (xyz.ndim() != 2 || xyz.shape(1) != 3) throw py::value_error("points must be (m, 3)");
  if (exact.ndim() != 2 || exact.shape(0) != xyz.shape(0) || exact.shape(1) != 3)
    throw py::value_error("exact must be the points in double, (m, 3)");
  if (local_origin.size() != 3) throw py::value_error("local_origin must be x, y, z");
  const auto m = static_cast<std::size_t>(xyz.shape(0));
  const auto n_own = static_cast<std::size_t>(own.size());
  LocalFitOptions options;
  const std::string chosen = choice("method", method, {"pca", "quadric", "robust"});
  options.method = chosen == "pca"       ? LocalFitMethod::PCA
                   : chosen == "quadric" ? LocalFitMethod::Quadric
                                         : LocalFitMethod::Robust;
  options.cloud_points = cloud_points;
  options.neighbourhood = NeighbourhoodKind::KdTree;
  options.k = k;
  options.radius = radius;
  options.max_neighbours = radius > 0.0 ? max_nn : 0;
  options.threads = threads;
  if (viewpoint.size() != 3) throw py::value_error("viewpoint must be x, y, z");
  options.viewpoint = Eigen::Vector3d(viewpoint[0], viewpoint[1], viewpoint[2]);
  if (choice("orient", orient, {"viewpoint", "up"}) == "up") {
    options.orientation = NormalOrientation::Up;
    if (up) options.up = Eigen::Vector3d((*up)[0], (*up)[1], (*up)[2]).normalized();
  }
  const Eigen::AlignedBox3d cloud_bounds = boxOf(bounds);
  const bool check = certify && radius == 0.0;
  Eigen::AlignedBox3d box;
  if (check) {
    if (!halo_box) throw py::value_error("certify needs the halo box");
    box = boxOf(*halo_box);
  }
  const bool robust = options.method == LocalFitMethod::Robust;
  const int floats = options.method == LocalFitMethod::Quadric ? 9 : robust ? 6 : 4;
  options.report_reaches = robust && check;
  py::array_t<float> records({static_cast<py::ssize_t>(n_own), static_cast<py::ssize_t>(floats)});
  py::array_t<bool> certified(static_cast<py::ssize_t>(n_own));
  py::array_t<double> looking(static_cast<py::ssize_t>(n_own));
  py::array_t<double> reaches(static_cast<py::ssize_t>(n_own));
  double* reach_of = reaches.mutable_data();
  float* rec = records.mutable_data();
  bool* ok = certified.mutable_data();
  double* look = looking.mutable_data();
  const float* p = xyz.data();
  const std::int64_t* own_at = own.data();
  LocalFitResult fit;
  std::int64_t failed = 0, fallback = 0;
  {
    py::gil_scoped_release release;
    auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    cloud->resize(m);
    for (std::size_t i = 0; i < m; ++i) {
      (*cloud)[i].x = p[3 * i];
      (*cloud)[i].y = p[3 * i + 1];
      (*cloud)[i].z = p[3 * i + 2];
    }
    LocalCloud local(cloud);
    local.positions = std::make_shared<Eigen::Matrix3Xd>(
        Eigen::Map<const Eigen::Matrix3Xd>(exact.data(), 3, static_cast<Eigen::Index>(m)));
    local.origin = Eigen::Vector3d(local_origin[0], local_origin[1], local_origin[2]);
    for (std::size_t j = 0; j < n_own; ++j) {
      if (own_at[j] < 0 || static_cast<std::size_t>(own_at[j]) >= m)
        throw pcl::BadArgumentException("own position outside the gathered points");
    }
    std::shared_ptr<LookingKdTree> search;
    if (check) {
      search = std::make_shared<LookingKdTree>(m, k);
      options.kd_tree_search = search;
    }
    auto indices = std::make_shared<pcl::Indices>(own_at, own_at + n_own);
    if (n_own > 0) fit = fitLocalSurfaces(local, nullptr, options, indices);
    // Certified by tile_certificate.h's rule, as fitTiles certifies.
    for (std::size_t j = 0; j < n_own; ++j) {
      ok[j] = true;
      look[j] = 0.0;
      reach_of[j] = std::numeric_limits<double>::infinity();
      if (!check) continue;
      const auto at = static_cast<std::size_t>(own_at[j]);
      reach_of[j] = haloReach((*cloud)[at].getVector3fMap().cast<double>(), box, cloud_bounds);
      look[j] = robust ? lookingDistance(search->squaredKth(at), fit.reaches[j])
                       : lookingDistance(search->squaredKth(at));
      ok[j] = look[j] <= reach_of[j];
    }
    // Counted over the certified points only (the others are fitted again after a wider gather):
    // a failed point has no normal, a quadric that fell back no curvatures.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t j = 0; j < n_own; ++j) {
      float* r = rec + j * floats;
      if (!ok[j]) {
        std::fill(r, r + floats, nan);
        continue;
      }
      const pcl::Normal& n = fit.normals[j];
      if (!std::isfinite(n.normal_x))
        ++failed;
      else if (floats == 9 && !std::isfinite(fit.curvatures[j].pc1))
        ++fallback;
      r[0] = n.normal_x;
      r[1] = n.normal_y;
      r[2] = n.normal_z;
      r[3] = n.curvature;
      if (robust) {
        r[4] = fit.scales[j];
        r[5] = fit.confidences[j];
      }
      if (floats == 9) {
        const pcl::PrincipalCurvatures& c = fit.curvatures[j];
        r[4] = c.pc1;
        r[5] = c.pc2;
        r[6] = c.principal_curvature_x;
        r[7] = c.principal_curvature_y;
        r[8] = c.principal_curvature_z;
      }
    }
  }
  return py::make_tuple(records, certified, looking, reaches, failed, fallback);
}

// The tools' fields for a fit (pcl_ddg_normals: setNormalFields; pcl_ddg_curvature -method
// quadric: the k1 direction, the normal fields, then mean, Gauss, k1 and k2), applied the way
// fit_steps.cpp's outOfCoreFields does for a piece.
void addFields(CloudPiece& input, const std::string& output, const std::string& tool,
               const std::vector<float>& records, int floats, FieldPrecision precision) {
  pcl::PCLPointCloud2& piece = input.cloud;
  const Eigen::Matrix3Xd& positions = input.positions;
  setVertexCoordinates(piece, positions, FieldPrecision::Float);
  const auto n = static_cast<Eigen::Index>(positions.cols());
  Eigen::Matrix3Xd normals(3, n);
  Eigen::VectorXd curvature(n), k1(n), k2(n), scale(n), confidence(n);
  Eigen::Matrix3Xd direction(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const float* r = records.data() + i * floats;
    // As normalsOf: the float normal widened to double.
    normals.col(i) = Eigen::Vector3f(r[0], r[1], r[2]).cast<double>();
    curvature[i] = r[3];
    if (floats == 6) {
      scale[i] = r[4];
      confidence[i] = r[5];
    }
    if (floats == 9) {
      k1[i] = r[4];
      k2[i] = r[5];
      direction.col(i) << r[6], r[7], r[8];
    }
  }
  const auto setNormals = [&] {
    const char* ply_names[] = {"nx", "ny", "nz"};
    const char* pcd_names[] = {"normal_x", "normal_y", "normal_z"};
    const bool pcd_naming = hasVertexField(piece, "normal_x") ? true
                            : hasVertexField(piece, "nx")
                                ? false
                                : fileExtension(output) == "pcd" || fileExtension(output) == "las";
    for (int d = 0; d < 3; ++d) removeVertexField(piece, pcd_naming ? ply_names[d] : pcd_names[d]);
    const char** names = pcd_naming ? pcd_names : ply_names;
    setVertexFields(piece, {names[0], names[1], names[2]}, normals, precision);
    setVertexField(piece, "curvature", curvature, precision);
  };
  if (tool == "curvature") {
    const char* names[] = {"k1_direction_x", "k1_direction_y", "k1_direction_z"};
    for (int d = 0; d < 3; ++d)
      setVertexField(piece, names[d], direction.row(d).transpose(), precision);
    setNormals();
    const Eigen::VectorXd mean = 0.5 * (k1 + k2);
    const Eigen::VectorXd gauss = k1.cwiseProduct(k2);
    setVertexField(piece, "mean_curvature", mean, precision);
    setVertexField(piece, "gauss_curvature", gauss, precision);
    setVertexField(piece, "k1", k1, precision);
    setVertexField(piece, "k2", k2, precision);
  } else {
    setNormals();
    if (floats == 6) {  // robust's, as FitFieldWriter adds them
      setVertexField(piece, "scale", scale, precision);
      setVertexField(piece, "confidence", confidence, precision);
    }
  }
  const FieldPrecision coordinates =
      input.coordinate_precision == FieldPrecision::Double || precision == FieldPrecision::Double
          ? FieldPrecision::Double
          : FieldPrecision::Float;
  setVertexCoordinates(piece, positions, coordinates);
}

/**
 * Writes `output` (binary PLY or PCD, or LAS in the first input's layout): the points of `inputs`,
 * in their order, each with its fields and the fit's (the results file holds `floats` float32 per
 * point of the concatenated inputs, from point `first_result` on), as the tool writes the merged
 * cloud. Atomic.
 */
std::int64_t writeOutput(const std::vector<std::string>& inputs, const std::string& output,
                         const std::string& results_path, std::int64_t first_result, int floats,
                         const std::string& tool, const std::string& precision_name,
                         std::int64_t piece_points, bool stream_pcd) {
  const std::string ext = fileExtension(output);
  if (ext != "ply" && ext != "pcd" && ext != "las" && ext != "laz")
    throw FileFormatException(output + ": the output must be .ply, .pcd, .las or .laz");
  choice("tool", tool, {"normals", "curvature"});
  const FieldPrecision precision =
      choice("precision", precision_name, {"float", "double"}) == "double" ? FieldPrecision::Double
                                                                           : FieldPrecision::Float;
  py::gil_scoped_release release;
  std::int64_t total = 0;
  std::vector<CloudFileLayout> layouts;
  std::shared_ptr<const LasLayout> las;  // a LAS output keeps the first input's layout
  for (const std::string& input : inputs) {
    const CloudPieceReader reader(input);
    if (layouts.empty()) las = reader.lasLayout();
    layouts.push_back(reader.layout());
    total += layouts.back().points;
  }
  if (inputs.empty()) throw pcl::BadArgumentException("no input");
  const int fd = ::open(results_path.c_str(), O_RDONLY);
  if (fd < 0) failSystem("cannot open " + results_path);
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  const bool single = inputs.size() == 1;
  const std::int64_t width = single ? layouts[0].width : total;
  const std::int64_t height = single ? layouts[0].height : 1;
  // A PCD as the tool writes it in memory (binary_compressed, which compresses the whole cloud
  // at once): the pieces are joined and saved by saveMesh. Else streamed (binary PLY, or binary
  // PCD as -memory writes it).
  const bool whole = ext == "pcd" && !stream_pcd;
  std::unique_ptr<AtomicFile> file;
  std::unique_ptr<CloudPieceWriter> out;
  pcl::PolygonMesh joined;
  if (!whole) {
    file = std::make_unique<AtomicFile>(output);
    out = std::make_unique<CloudPieceWriter>(
        file->temporaryPath(), ext, total, static_cast<std::uint32_t>(width),
        static_cast<std::uint32_t>(height), layouts[0].sensor_pose, las);
  }
  std::int64_t at = first_result;
  std::vector<float> records;
  for (std::size_t f = 0; f < inputs.size(); ++f) {
    CloudPieceReader pieces(inputs[f]);
    const std::int64_t points = layouts[f].points;
    for (std::int64_t first = 0; first < points; first += piece_points) {
      const std::int64_t count = std::min(piece_points, points - first);
      CloudPiece input = pieces.read(first, count);
      pcl::PCLPointCloud2& piece = input.cloud;
      records.resize(static_cast<std::size_t>(count * floats));
      const std::size_t bytes = records.size() * sizeof(float);
      if (::pread(fd, records.data(), bytes, static_cast<off_t>(at * floats * 4)) !=
          static_cast<ssize_t>(bytes))
        failSystem("cannot read the results " + results_path);
      addFields(input, output, tool, records, floats, precision);
      at += count;
      if (!whole) {
        out->write(piece);
        continue;
      }
      if (joined.cloud.data.empty() && joined.cloud.fields.empty()) {
        joined.cloud = std::move(piece);
        joined.cloud.data.reserve(static_cast<std::size_t>(total) * joined.cloud.point_step);
      } else {
        const auto same = [](const pcl::PCLPointField& a, const pcl::PCLPointField& b) {
          return a.name == b.name && a.offset == b.offset && a.datatype == b.datatype &&
                 a.count == b.count;
        };
        if (piece.point_step != joined.cloud.point_step ||
            !std::equal(piece.fields.begin(), piece.fields.end(), joined.cloud.fields.begin(),
                        joined.cloud.fields.end(), same))
          throw FileFormatException(inputs[f] + ": its fields differ from the first input's");
        joined.cloud.data.insert(joined.cloud.data.end(), piece.data.begin(), piece.data.end());
        joined.cloud.is_dense = joined.cloud.is_dense && piece.is_dense;
      }
    }
  }
  if (!whole) {
    out->close();
    file->commit();
    return total;
  }
  joined.cloud.width = static_cast<std::uint32_t>(width);
  joined.cloud.height = static_cast<std::uint32_t>(height);
  joined.cloud.row_step = joined.cloud.point_step * joined.cloud.width;
  MeshWriteOptions write_options;
  write_options.sensor_pose = layouts[0].sensor_pose;
  saveMesh(output, joined, write_options);
  return total;
}

}  // namespace

/**
 * The runner's k and max_nn from what it was given, checked as the tools check them (their
 * spelling: the runner's messages name the tools' options): (k, max_nn).
 */
py::tuple fitRequest(const std::string& method, std::optional<int> k, std::optional<double> radius,
                     std::optional<int> max_nn, std::optional<std::string> orient, bool viewpoint,
                     bool up) {
  FitRequest request;
  request.k = k;
  request.radius = radius;
  request.max_nn = max_nn;
  request.orient = std::move(orient);
  request.viewpoint = viewpoint;
  request.up = up;
  checkFitRequest(request, kToolStyle);
  LocalFitOptions options;
  options.method = chooseFitMethod(method, kToolStyle);
  // Each tile checks k against its points; the runner against the whole input's.
  applyNeighbourCounts(request, std::numeric_limits<std::int64_t>::max(), kToolStyle, options);
  return py::make_tuple(options.k, max_nn.value_or(static_cast<int>(kDefaultMaxNeighbours)));
}

void bindDistributed(py::module_& m) {
  m.def("_radius_halo", &radiusHalo, py::arg("radius"),
        "The halo that certifies radius searches (tile_certificate.h).");
  m.def("_fit_request", &fitRequest, py::arg("method"), py::arg("k"), py::arg("radius"),
        py::arg("max_nn"), py::arg("orient"), py::arg("viewpoint"), py::arg("up"),
        "The runner's (k, max_nn), checked as the tools check them.");
  m.def("_parse_byte_size", &parseByteSize, py::arg("text"),
        "Bytes of a size like 2G, 512MB or 64k (powers of 1024), as the tools' -memory reads it.");
  m.def("_cloud_layout", &cloudLayout, py::arg("path"),
        "How a binary PCD/PLY or LAS/LAZ cloud lies on disk (header only): points, "
        "header_bytes, point_bytes, width, height, viewpoint, orientation, fields, chunks (a LAZ "
        "file's (first, count) per chunk, else None).");
  m.def("_read_positions", &readPositions, py::arg("path"), py::arg("first"), py::arg("count"),
        "Points [first, first + count) of a cloud file as float64 (n, 3), read by their byte "
        "range, exact (LAS: X * scale + offset).");
  m.def(
      "_local_origin",
      [](const std::vector<double>& bounds) {
        if (bounds.size() != 6)
          throw py::value_error("bounds are (xmin, ymin, zmin, xmax, ymax, zmax)");
        Eigen::AlignedBox3d box(Eigen::Vector3d(bounds[0], bounds[1], bounds[2]),
                                Eigen::Vector3d(bounds[3], bounds[4], bounds[5]));
        const Eigen::Vector3d o = localOrigin(box);
        return std::vector<double>{o.x(), o.y(), o.z()};
      },
      py::arg("bounds"),
      "The local origin of points within these bounds (local_cloud.h): what the tools centre "
      "a cloud on before its floats are searched.");
  m.def(
      "_result_warnings",
      [](const std::vector<double>& bounds, const std::string& orient,
         const std::vector<double>& viewpoint, std::int64_t failed, std::int64_t fallback) {
        if (bounds.size() != 6 || viewpoint.size() != 3)
          throw py::value_error("bounds are 6 numbers, the viewpoint 3");
        LocalFitOptions options;
        options.orientation = choice("orient", orient, {"viewpoint", "up"}) == "up"
                                  ? NormalOrientation::Up
                                  : NormalOrientation::Viewpoint;
        options.viewpoint = Eigen::Vector3d(viewpoint[0], viewpoint[1], viewpoint[2]);
        std::vector<std::string> messages;
        if (auto message = farViewpointWarning(Eigen::Vector3d(bounds[0], bounds[1], bounds[2]),
                                               Eigen::Vector3d(bounds[3], bounds[4], bounds[5]),
                                               options, {"-viewpoint x,y,z", "-orient up"}))
          messages.push_back(std::move(*message));
        for (std::string& message : fitResultWarnings(failed, fallback))
          messages.push_back(std::move(message));
        return messages;
      },
      py::arg("bounds"), py::arg("orient"), py::arg("viewpoint"), py::arg("failed"),
      py::arg("fallback"),
      "What pcl_ddg_normals warns about a run on the merged cloud within bounds "
      "(result_warnings.h): a viewpoint too far to orient by, points without an estimate.");
  m.def("_gather_chunk", &gatherChunk, py::arg("path"), py::arg("first"), py::arg("count"),
        py::arg("lo"), py::arg("hi"), py::arg("origin"), py::arg("size"), py::arg("dims"),
        py::arg("tile"), py::arg("local_origin"),
        "A chunk's points relative to local_origin inside the box [lo, hi] and the tile's own "
        "(grid cells of the given origin, size and dims): (float32 points, float64 points, "
        "positions in the chunk, own mask).");
  m.def("_fit_tile", &fitTile, py::arg("points"), py::arg("exact"), py::arg("local_origin"),
        py::arg("own"), py::arg("method"), py::arg("k"), py::arg("radius"), py::arg("max_nn"),
        py::arg("viewpoint"), py::arg("orient"), py::arg("up"), py::arg("halo_box"),
        py::arg("bounds"), py::arg("mode"), py::arg("threads"), py::arg("cloud_points") = 0,
        "Fits a tile's own points among its gathered points (merged-cloud order); mode "
        "'certified': the fits of the points whose look (k-th neighbour; robust: and the rows "
        "its wider planes read) stays nearer than the halo's edge count, 'all': every own "
        "point's. cloud_points: the merged cloud's finite points (robust's scale).");
  m.def("_write_output", &writeOutput, py::arg("inputs"), py::arg("output"), py::arg("results"),
        py::arg("first_result"), py::arg("floats"), py::arg("tool"), py::arg("precision"),
        py::arg("piece_points") = std::int64_t{1} << 18, py::arg("stream_pcd") = false,
        "Writes the inputs' points with the fitted fields as the tool writes the merged cloud.");
}

}  // namespace python
}  // namespace pcl_ddg
