#include "common/tool_input.h"

#include <pcl/common/point_tests.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/tool_common.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace tools {
namespace {

// Room for what a tool adds to a LAS or PCD cloud's rows in place: double coordinates, normals and
// curvature in double, robust's scale and confidence (reserved, not touched until written).
constexpr std::size_t kSparePointBytes = 24 + 4 * 8 + 2 * 8;

// Moves the finite points by `by`: exact both ways about a local origin (local_cloud.h), which
// holds for the points its box was made of; a point with a NaN coordinate is left as read (it is
// no one's neighbour, its other coordinates may lie anywhere). Axes not moved are not touched,
// as localCoordinate and worldCoordinate leave them.
void moveFinitePoints(Eigen::Matrix3Xd& positions, const Eigen::Vector3d& by) {
  for (int d = 0; d < 3; ++d) {
    if (by[d] == 0.0) continue;
    for (Eigen::Index i = 0; i < positions.cols(); ++i)
      if (positions.col(i).allFinite()) positions(d, i) += by[d];
  }
}

}  // namespace

ToolInput::ToolInput(const std::string& path, const char* tool_name, InputKind kind) {
  MeshFile file;
  {
    Timer timer("Loading " + path);
    file = readMeshFile(path, EmptyFilePolicy::Refuse, FaceStorage::Rows, kSparePointBytes);
    timer.done(static_cast<std::size_t>(file.positions.cols()));
  }
  const bool has_faces = file.faces || !file.mesh.polygons.empty();
  if (kind == InputKind::Mesh && !has_faces)
    throw std::runtime_error(path + " has no faces (a point cloud?)");
  mesh = std::move(file.mesh);
  faces = std::move(file.faces);
  positions_ = std::make_shared<Eigen::Matrix3Xd>(std::move(file.positions));
  point_count_ = positions_->cols();
  const Eigen::Matrix3Xd& positions = *positions_;
  sensor_pose = file.sensor_pose;
  las = std::move(file.las);
  coordinate_precision = file.coordinate_precision;
  if (!has_faces) {
    const NonFiniteVertices bad = findNonFiniteVertices(positions);
    if (bad.count == positions.cols()) throw std::runtime_error(path + " has no finite point");
    if (bad.count > 0)
      warn(tool_name, std::to_string(bad.count) + " non-finite points (NaN output there)");
    return;
  }
  Timer timer("Building the mesh topology");
  requireFinite(positions);
  topology = faces ? std::make_shared<const MeshTopology>(
                         static_cast<int>(mesh.cloud.width * mesh.cloud.height),
                         PolygonList(faces->indices.data(), faces->rows(), faces->corners))
                   : std::make_shared<const MeshTopology>(mesh);
  // Faces that are the topology's triangles, in order (triangles, none dropped or split), are
  // kept once, by the topology, and written out from it (outputFaces).
  const Eigen::Matrix3Xi& triangles = topology->triangles();
  if (faces && faces->corners == 3 &&
      faces->indices.size() == static_cast<std::size_t>(triangles.size()) &&
      std::equal(faces->indices.begin(), faces->indices.end(), triangles.data()))
    faces.reset();
  // Only the defects worth a warning (pcl_ddg_info makes the whole MeshReport).
  const TopologyCounts& counts = topology->counts();
  const std::int64_t degenerate =
      counts.repeated_index_polygons + countZeroAreaFaces(*topology, positions);
  timer.done(static_cast<std::size_t>(positions.cols()));

  const std::pair<std::int64_t, const char*> defects[] = {
      {degenerate, "degenerate faces (no weight)"},
      {counts.duplicate_polygons, "duplicate faces"},
      {counts.nonmanifold_edges, "non-manifold edges"},
      {counts.nonmanifold_vertices, "non-manifold (bow-tie) vertices"},
      {counts.unreferenced_vertices, "unreferenced vertices (NaN results)"}};
  for (const auto& [count, what] : defects) {
    if (count > 0) warn(tool_name, std::to_string(count) + " " + what);
  }
}

const Eigen::Matrix3Xd& ToolInput::positions() const {
  if (held_ == Held::InRows) {
    *positions_ = vertexPositions(mesh.cloud, NonFinitePolicy::Keep);
    held_ = Held::AsRead;
  }
  if (held_ != Held::AsRead)
    throw std::logic_error(
        "ToolInput::positions() while local() holds them (releaseLocal() first)");
  return *positions_;
}

BoundingBox ToolInput::bounds() const {
  if (held_ == Held::InRows) positions();  // made again from the rows
  if (held_ == Held::AsRead) return boundingBox(*positions_);
  BoundingBox box;
  if (held_ == Held::Shifted) {
    box = boundingBox(*positions_);
  } else {
    box.min.setConstant(std::numeric_limits<double>::infinity());
    box.max.setConstant(-std::numeric_limits<double>::infinity());
    for (const pcl::PointXYZ& p : *points_) {
      box.min = box.min.cwiseMin(p.getVector3fMap().cast<double>());
      box.max = box.max.cwiseMax(p.getVector3fMap().cast<double>());
    }
  }
  // Exact: each point about the origin plus the origin is the one read.
  box.min += local_->origin;
  box.max += local_->origin;
  return box;
}

void ToolInput::restoreFromFloats() {
  positions_->resize(3, point_count_);
  const Eigen::Vector3d& origin = local_->origin;
  for (Eigen::Index i = 0; i < point_count_; ++i) {
    const Eigen::Vector3f& p = (*points_)[static_cast<std::size_t>(i)].getVector3fMap();
    for (int d = 0; d < 3; ++d) (*positions_)(d, i) = worldCoordinate(p[d], origin[d]);
  }
  held_ = Held::AsRead;
}

bool ToolInput::localFromFloatRows(const Eigen::Vector3d& origin) {
  if (topology) return false;
  const pcl::PCLPointCloud2& cloud = mesh.cloud;
  std::uint32_t offsets[3];
  for (int d = 0; d < 3; ++d) {
    const auto field = std::find_if(cloud.fields.begin(), cloud.fields.end(), [&](const auto& f) {
      return f.name == std::string(1, "xyz"[d]) && f.datatype == pcl::PCLPointField::FLOAT32 &&
             f.count == 1;
    });
    if (field == cloud.fields.end()) return false;
    offsets[d] = field->offset;
  }
  // The rows' floats are the positions read (a float file's), each to the bit, and all finite:
  // decided before the doubles go. (About this origin, the positions' own, their floats hold
  // them: localCloudOfFloats does not refuse them.)
  const Eigen::Matrix3Xd& read = *positions_;
  for (Eigen::Index i = 0; i < point_count_; ++i) {
    const std::uint8_t* row = cloud.data.data() + static_cast<std::size_t>(i) * cloud.point_step;
    for (int d = 0; d < 3; ++d) {
      float value;
      std::memcpy(&value, row + offsets[d], sizeof value);
      const double widened = value;
      if (!std::isfinite(value) || std::memcmp(&widened, &read(d, i), sizeof widened) != 0)
        return false;
    }
  }
  Eigen::Matrix3Xd().swap(*positions_);  // in the rows: not a third copy beside rows and floats
  held_ = Held::InRows;
  LocalCloud floats = localCloudOfFloats(cloud.data.data(), cloud.point_step, offsets,
                                         static_cast<std::size_t>(point_count_), origin,
                                         cloud.height > 1 ? cloud.width : 0);
  if (!floats.points || !floats.points->is_dense) {  // not after the checks above
    positions();  // made again from the rows, for local()'s usual way
    return false;
  }
  local_ = std::move(floats);
  points_ = std::const_pointer_cast<pcl::PointCloud<pcl::PointXYZ>>(local_->points);
  held_ = Held::InFloats;
  return true;
}

const LocalCloud& ToolInput::local() {
  if (local_) return *local_;
  if (held_ == Held::InRows) positions();  // made again from the rows
  const Eigen::Vector3d origin = localOrigin(*positions_);
  if (localFromFloatRows(origin)) {
    points_->sensor_origin_.head<3>() = (sensor_pose.origin - local_->origin).cast<float>();
    points_->sensor_orientation_ = sensor_pose.orientation.cast<float>();
    return *local_;
  }
  moveFinitePoints(*positions_, -origin);
  try {
    // An organized cloud (a frame, a range image) keeps its pixel grid and its sensor.
    local_ =
        localCloudOf(positions_, origin, !topology && mesh.cloud.height > 1 ? mesh.cloud.width : 0);
  } catch (...) {
    moveFinitePoints(*positions_, origin);
    throw;
  }
  points_ = std::const_pointer_cast<pcl::PointCloud<pcl::PointXYZ>>(local_->points);
  held_ = Held::Shifted;
  if (!local_->positions) {  // the floats hold them exactly: no doubles shared
    moveFinitePoints(*positions_, origin);
    held_ = Held::AsRead;
    if (!topology && points_->is_dense) {
      // A cloud's floats about the origin are its coordinates, to the last bit: until
      // releaseLocal() they are the only copy (a float cloud's fit needs 24 bytes a point less).
      Eigen::Matrix3Xd().swap(*positions_);
      held_ = Held::InFloats;
    }
  }
  points_->sensor_origin_.head<3>() = (sensor_pose.origin - local_->origin).cast<float>();
  points_->sensor_orientation_ = sensor_pose.orientation.cast<float>();
  return *local_;
}

const pcl::PointCloud<pcl::PointXYZ>::Ptr& ToolInput::points() {
  local();
  return points_;
}

std::shared_ptr<const FaceRows> ToolInput::outputFaces() const {
  if (faces || !topology || !mesh.polygons.empty()) return faces;
  auto rows = std::make_shared<FaceRows>();
  const Eigen::Matrix3Xi& triangles = topology->triangles();
  rows->indices.assign(triangles.data(), triangles.data() + triangles.size());
  return rows;
}

void ToolInput::separateLocal() {
  local();
  if (held_ == Held::InFloats) restoreFromFloats();
  if (held_ != Held::Shifted) return;
  local_->positions = std::make_shared<Eigen::Matrix3Xd>(*positions_);
  moveFinitePoints(*positions_, local_->origin);
  held_ = Held::AsRead;
}

float ToolInput::rowCoordinate(const pcl::PointXYZ& p, int d) const {
  return static_cast<float>(worldCoordinate(p.data[d], local_->origin[d]));
}

bool ToolInput::lendRows() {
  local();
  pcl::PCLPointCloud2& cloud = mesh.cloud;
  const auto axis = [&](std::size_t k, const char* name) {
    const pcl::PCLPointField& f = cloud.fields[k];
    return f.name == name && f.offset == 4 * k && f.datatype == pcl::PCLPointField::FLOAT32 &&
           f.count == 1;
  };
  if (rows_lent_ || held_ != Held::InFloats || cloud.fields.size() != 3 || cloud.point_step != 12 ||
      !axis(0, "x") || !axis(1, "y") || !axis(2, "z") || !rowsHoldTheFloats())
    return false;
  cloud.fields.clear();
  cloud.point_step = 0;
  cloud.row_step = 0;
  cloud.data.clear();  // its block kept: the new fields' rows are made in it
  rows_lent_ = true;
  return true;
}

void ToolInput::returnRows() {
  if (!rows_lent_) return;
  pcl::PCLPointCloud2& cloud = mesh.cloud;
  const std::uint32_t step = cloud.point_step, wider = step + 12;
  const auto count = static_cast<std::size_t>(point_count_);
  // Back to front, as relayout() grows rows: row i's new place covers only rows moved already and
  // its own old bytes, copied aside first.
  cloud.data.resize(count * wider);
  std::vector<std::uint8_t> row(step);
  for (std::size_t i = count; i-- > 0;) {
    std::uint8_t* to = cloud.data.data() + i * wider;
    if (step > 0) std::memcpy(row.data(), cloud.data.data() + i * step, step);
    for (int d = 0; d < 3; ++d) {
      const float coordinate = rowCoordinate((*points_)[i], d);
      std::memcpy(to + 4 * d, &coordinate, 4);
    }
    if (step > 0) std::memcpy(to + 12, row.data(), step);
  }
  for (pcl::PCLPointField& field : cloud.fields) field.offset += 12;
  std::vector<pcl::PCLPointField> fields(3);
  for (int d = 0; d < 3; ++d) {
    fields[d].name = std::string(1, "xyz"[d]);
    fields[d].offset = 4 * d;
    fields[d].datatype = pcl::PCLPointField::FLOAT32;
    fields[d].count = 1;
  }
  cloud.fields.insert(cloud.fields.begin(), fields.begin(), fields.end());
  cloud.point_step = wider;
  cloud.row_step = wider * cloud.width;
  rows_lent_ = false;
}

bool ToolInput::rowsHoldTheFloats() const {
  const auto field = [&](const char* name) -> const pcl::PCLPointField* {
    for (const pcl::PCLPointField& f : mesh.cloud.fields)
      if (f.name == name && f.datatype == pcl::PCLPointField::FLOAT32 && f.count == 1) return &f;
    return nullptr;
  };
  const pcl::PCLPointField* axes[] = {field("x"), field("y"), field("z")};
  if (!axes[0] || !axes[1] || !axes[2]) return false;
  const Eigen::Vector3d& origin = local_->origin;
  const std::uint8_t* row = mesh.cloud.data.data();
  for (Eigen::Index i = 0; i < point_count_; ++i, row += mesh.cloud.point_step) {
    const pcl::PointXYZ& p = (*points_)[static_cast<std::size_t>(i)];
    for (int d = 0; d < 3; ++d) {
      // As restoreFromFloats() would restore it: a float, and the row's to the bit (rowCoordinate).
      const double restored = worldCoordinate(p.data[d], origin[d]);
      const auto written = static_cast<float>(restored);
      if (!floatHolds(restored) ||
          std::memcmp(&written, row + axes[d]->offset, sizeof written) != 0)
        return false;
    }
  }
  return true;
}

void ToolInput::releaseLocal() {
  returnRows();
  if (held_ == Held::InFloats) {
    if (rowsHoldTheFloats()) {  // a float file's cloud: its rows are its coordinates
      points_.reset();
      local_.reset();
      held_ = Held::InRows;
      return;
    }
    restoreFromFloats();
  }
  if (held_ == Held::Shifted) moveFinitePoints(*positions_, local_->origin);
  held_ = Held::AsRead;
  points_.reset();
  local_.reset();
}

double ToolInput::spacing() {
  if (!spacing_)
    spacing_ = topology ? meanEdgeLength(*topology, *positions_) : meanSpacing(points());
  return *spacing_;
}

double meanSpacing(const pcl::PointCloud<pcl::PointXYZ>::Ptr& points) {
  pcl::Indices finite;
  for (std::size_t i = 0; i < points->size(); ++i) {
    if (pcl::isXYZFinite((*points)[i])) finite.push_back(static_cast<pcl::index_t>(i));
  }
  if (finite.size() < 2) return 0.0;
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(points, std::make_shared<const pcl::Indices>(finite));
  const std::size_t step = std::max<std::size_t>(1, finite.size() / 10000);
  double sum = 0.0;
  std::size_t counted = 0;
  pcl::Indices found;
  std::vector<float> distances;
  for (std::size_t i = 0; i < finite.size(); i += step) {
    // Exact duplicates are skipped: the spacing is between distinct samples.
    if (tree.nearestKSearch((*points)[finite[i]], 8, found, distances) < 2) continue;
    for (const float d : distances) {
      if (d > 0.0f) {
        sum += std::sqrt(d);
        ++counted;
        break;
      }
    }
  }
  return counted > 0 ? sum / counted : 0.0;
}

}  // namespace tools
}  // namespace pcl_ddg
