#pragma once
// What the tools write: new vertex fields under the names the output format expects, in the
// precision asked for, and the result saved atomically with the input's layout.
#include <pcl/PolygonMesh.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <string>

#include "common/tool_common.h"
#include "common/tool_input.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"

namespace pcl_ddg {
namespace tools {

/** -precision float|double. */
FieldPrecision precisionArgument(const ToolArguments& args);

/**
 * Writes normals (3 x N) as one field triple: under the input's own names when it has normals
 * (nx ny nz, or normal_x normal_y normal_z), else under the output format's (PLY nx ny nz, PCD
 * normal_x normal_y normal_z, as PCL writes them; LAS like PCD, written as PDAL's NormalX NormalY
 * NormalZ). The other naming is removed, so no output ever
 * holds two normal triples.
 */
void setNormalTriple(pcl::PCLPointCloud2& cloud, const std::string& output_path,
                     const Eigen::Matrix3Xd& normals, FieldPrecision precision);

/** Writes normals as nx ny nz (PLY) or normal_x normal_y normal_z (PCD), and PCL's curvature
 *  (surface variation) as "curvature". */
void setNormalFields(pcl::PCLPointCloud2& cloud, const std::string& output_path,
                     const pcl::PointCloud<pcl::Normal>& normals, FieldPrecision precision);

/** setNormalFields, and robust's scale and confidence (the neighbours it used, its confidence),
 *  written a slice of points at a time as fitLocalSurfacesInSlices hands them over: the fields
 *  are laid out (NaN) with the first slice, in the order and precision setNormalFields and
 *  setVertexField give them. */
class FitFieldWriter {
 public:
  FitFieldWriter(pcl::PCLPointCloud2& cloud, const std::string& output_path,
                 FieldPrecision precision, bool robust_scores);
  void write(std::size_t first, const LocalFitResult& slice);

 private:
  pcl::PCLPointCloud2& cloud_;
  std::vector<std::string> normal_names_;
  FieldPrecision precision_;
  bool robust_scores_;
  bool laid_out_ = false;
};

/** The normals of a PCL estimator as a 3 x N matrix (NaN kept). */
Eigen::Matrix3Xd normalsOf(const pcl::PointCloud<pcl::Normal>& normals);

/**
 * Colours the output by a colour map of `values` (the field `field_name`), replacing the input's
 * own colours and saying so; a PLY output also gets the values as `quality` (what MeshLab's
 * quality tools read), unless the input has a quality field of its own.
 */
void setColorMapFields(const char* tool_name, pcl::PCLPointCloud2& cloud,
                       const std::string& output_path, const std::string& field_name,
                       const Eigen::VectorXd& values, const VertexColors& colors);

/** The precision of an output's coordinates: double when the input declared them double or
 *  -precision double asks for it, float otherwise. */
FieldPrecision coordinatePrecision(FieldPrecision input, FieldPrecision requested);

/**
 * Writes positions into the mesh as x, y, z in the given precision and saves it through saveMesh
 * (format by extension, atomic), with a timing line; a PCD output carries the sensor pose as its
 * VIEWPOINT, a LAS output the input's LAS layout (`las`: version, point format, scale, offset,
 * VLRs; null for a new LAS 1.4 file). Warns when a .pcd gets double fields, which PCL's float point
 * types cannot read. A mesh read as rows (ToolInput::faces) writes them as such.
 */
void saveResult(const char* tool_name, const std::string& path, pcl::PolygonMesh& mesh,
                const Eigen::Matrix3Xd& positions, FieldPrecision coordinates,
                const SensorPose& sensor_pose = {},
                const std::shared_ptr<const LasLayout>& las = nullptr,
                const std::shared_ptr<const FaceRows>& faces = nullptr);

/** saveResult of an input with its own coordinates, in coordinatePrecision(its precision,
 *  requested), its sensor pose, LAS layout and faces; a cloud whose float rows hold the
 *  coordinates (ToolInput::coordinatesInRows) is written as it is, without its doubles made
 *  again (24 bytes a point). */
void saveResult(const char* tool_name, const std::string& path, ToolInput& in,
                FieldPrecision requested);

}  // namespace tools
}  // namespace pcl_ddg
