#pragma once
// An input file as every tool loads it: the file (mesh or cloud, exact coordinates, what the format
// declares), a mesh's topology checked once with one warning line per kind of defect, and what
// only some tools need (the points about their local origin, the sampling's spacing) made on
// first use.
#include <pcl/PolygonMesh.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>

#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/local_cloud.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {
namespace tools {

enum class InputKind {
  Any,  ///< a mesh or a point cloud
  Mesh  ///< faces required: a cloud is refused
};

class ToolInput {
 public:
  /** Loads with a timing line. A mesh: non-finite coordinates and out-of-range indices throw, its
   *  defects are warned about (degenerate, duplicate, non-manifold, unreferenced). A cloud: the
   *  non-finite points are counted in a warning (kept: NaN output there); none finite throws. */
  ToolInput(const std::string& path, const char* tool_name, InputKind kind = InputKind::Any);
  // Not copied: a copy would share the positions local() shifts and shift them back twice.
  ToolInput(const ToolInput&) = delete;
  ToolInput& operator=(const ToolInput&) = delete;
  ToolInput(ToolInput&&) = default;
  ToolInput& operator=(ToolInput&&) = default;

  /** x, y, z as float (PCL's point types; positions holds them exactly); its polygons empty when
   *  the faces are rows. */
  pcl::PolygonMesh mesh;
  /** A mesh's faces of one size (FaceStorage::Rows); null once the topology holds them (a mesh
   *  of triangles: outputFaces() writes them from it). */
  std::shared_ptr<const FaceRows> faces;
  std::shared_ptr<const MeshTopology> topology;  ///< null for a cloud
  SensorPose sensor_pose;                        ///< a PCD's VIEWPOINT (kept for the output)
  std::shared_ptr<const LasLayout> las;          ///< a LAS input's layout (for a .las output)
  FieldPrecision coordinate_precision = FieldPrecision::Float;  ///< as the file declares them

  /** The coordinates in double, as read (LAS: X * scale + offset). Throws std::logic_error
   *  while local() holds them about its origin (until releaseLocal()). */
  const Eigen::Matrix3Xd& positions() const;
  /** The coordinates are mesh.cloud's float x, y, z alone (a float cloud after releaseLocal()):
   *  writing positions() there as floats would change no bit. */
  bool coordinatesInRows() const { return held_ == Held::InRows; }
  Eigen::Index pointCount() const { return point_count_; }
  /** The bounding box of the finite positions, in world coordinates, whenever asked. */
  BoundingBox bounds() const;

  /** positions about their local origin (local_cloud.h): what every fit takes. Its float points
   *  keep an organized cloud's grid, and the sensor pose is their sensor_origin_ (relative to
   *  the origin) and sensor_orientation_. Made on the first call, from positions shifted in place
   *  (x - origin is exact, and so is the way back), not from a copy: a 10M-point LAS file's fit
   *  needs 240 MB less; a cloud whose floats hold its coordinates keeps only them until
   *  releaseLocal(). */
  const LocalCloud& local();
  /** Gives local() positions of its own (a copy), so that they may change (-classes makes points
   *  NaN) while positions() keeps the coordinates read. */
  void separateLocal();
  /** local()'s float points, to change after separateLocal() (a point made NaN is left out of
   *  the fits; without separateLocal() a float cloud's change would reach the output, whose
   *  coordinates they are until releaseLocal()). */
  const pcl::PointCloud<pcl::PointXYZ>::Ptr& points();
  /** The faces to write with the output (saveResult): faces, or the topology's triangles when
   *  faces was let go for them; null for a cloud or polygons. */
  std::shared_ptr<const FaceRows> outputFaces() const;
  /** Lends mesh.cloud's rows to the fields a fit adds while local()'s floats hold the
   *  coordinates: when the rows are a float cloud's x, y, z alone (12 bytes a point) and the floats
   *  restore them to the bit, the rows lose their fields (point_step 0, the bytes kept), so that
   *  the new fields take the coordinates' place instead of coming on top of them, until
   *  returnRows() puts x, y, z back in front. Returns whether it lent them (false: the rows are
   *  left as they are). A 10M-point PCD's fit then holds 12 bytes a point less at its peak. */
  bool lendRows();
  /** After lendRows(): x, y, z back in front of the fields added, from local()'s floats (in
   *  place when the reader reserved room in the rows, as for PCD and LAS; else the rows grow).
   *  Nothing when the rows were not lent. */
  void returnRows();
  /** Frees local() once the fits are done (the output needs positions and the cloud only), and
   *  shifts positions back to the coordinates read: local()'s memory is then free for the
   *  output's fields. A later local() makes it anew, without the changes made through points().
   *  A float cloud whose rows hold its coordinates as its floats did (checked bit for bit) keeps
   *  them there alone: positions() makes the doubles again only when asked, and saveResult
   *  writes the rows as they are. */
  void releaseLocal();
  /** h: a mesh's mean edge length, a cloud's mean distance to the nearest other point (over up to
   *  10,000 points, exact duplicates skipped: it costs a kd-tree). Measured on the first call. */
  double spacing();

 private:
  /** Where the coordinates read are while local() lives: positions_ as read, positions_ about
   *  local_->origin (shared with local_), only in local_'s floats (positions_ empty), or only in
   *  mesh.cloud's float x, y, z (after releaseLocal(); positions_ empty). */
  enum class Held { AsRead, Shifted, InFloats, InRows };
  /** local_ straight from a float cloud's rows (their floats are the positions read, and the
   *  points about origin hold them exactly, all finite: checked first): positions_ is let go
   *  before the points are made, so that the rows, the doubles and the floats are never all held
   *  at once (a 10M-point float PCD's peak). False, positions_ as read, otherwise. */
  bool localFromFloatRows(const Eigen::Vector3d& origin);
  /** positions_ from local_'s floats, exactly the coordinates read. */
  void restoreFromFloats();
  /** Whether mesh.cloud's float x, y, z are the coordinates restoreFromFloats() would make,
   *  exactly. */
  bool rowsHoldTheFloats() const;
  /** The coordinate of axis d of point p as the float the rows held (restoreFromFloats()'s). */
  float rowCoordinate(const pcl::PointXYZ& p, int d) const;

  std::shared_ptr<Eigen::Matrix3Xd> positions_;
  Eigen::Index point_count_ = 0;
  mutable Held held_ = Held::AsRead;  ///< positions() makes InRows' doubles when asked
  std::optional<LocalCloud> local_;
  pcl::PointCloud<pcl::PointXYZ>::Ptr points_;  ///< local_'s, not const
  std::optional<double> spacing_;
  bool rows_lent_ = false;  ///< lendRows(): the rows hold the new fields alone
};

/** Mean distance from a point to its nearest other point (exact duplicates skipped), over up to
 *  10,000 finite points: a cloud's h. */
double meanSpacing(const pcl::PointCloud<pcl::PointXYZ>::Ptr& points);

}  // namespace tools
}  // namespace pcl_ddg
