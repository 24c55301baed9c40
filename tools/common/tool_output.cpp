#include "common/tool_output.h"

#include <iostream>

#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace tools {

FieldPrecision precisionArgument(const ToolArguments& args) {
  return args.choice("precision", {"float", "double"}, "float") == "double" ? FieldPrecision::Double
                                                                            : FieldPrecision::Float;
}

namespace {

// The names of the output's normal triple; the other naming's fields are removed.
std::vector<std::string> normalNames(pcl::PCLPointCloud2& cloud, const std::string& output_path) {
  const char* ply_names[] = {"nx", "ny", "nz"};
  const char* pcd_names[] = {"normal_x", "normal_y", "normal_z"};
  const bool pcd_naming = hasVertexField(cloud, "normal_x") ? true
                          : hasVertexField(cloud, "nx")     ? false
                                                            : fileExtension(output_path) == "pcd" ||
                                                              fileExtension(output_path) == "las" ||
                                                              fileExtension(output_path) == "laz";
  for (int d = 0; d < 3; ++d) removeVertexField(cloud, pcd_naming ? ply_names[d] : pcd_names[d]);
  const char** names = pcd_naming ? pcd_names : ply_names;
  return {names[0], names[1], names[2]};
}

// Rows first .. first + rows - 1 of the floats of a cloud of pcl::Normal (normal_x, normal_y,
// normal_z, padding, curvature, ...: 8 floats a point), one column per point, where they lie.
Eigen::Map<const Eigen::MatrixXf, 0, Eigen::OuterStride<>> normalRows(
    const pcl::PointCloud<pcl::Normal>& normals, int first, int rows) {
  static_assert(sizeof(pcl::Normal) == 8 * sizeof(float), "pcl::Normal is 8 floats");
  static const float none[8] = {};
  const float* base =
      normals.empty() ? none : reinterpret_cast<const float*>(normals.points.data());
  return {base + first, rows, static_cast<Eigen::Index>(normals.size()), Eigen::OuterStride<>(8)};
}

}  // namespace

void setNormalTriple(pcl::PCLPointCloud2& cloud, const std::string& output_path,
                     const Eigen::Matrix3Xd& normals, FieldPrecision precision) {
  setVertexFields(cloud, normalNames(cloud, output_path), normals, precision);
}

void setNormalFields(pcl::PCLPointCloud2& cloud, const std::string& output_path,
                     const pcl::PointCloud<pcl::Normal>& normals, FieldPrecision precision) {
  setVertexFields(cloud, normalNames(cloud, output_path), normalRows(normals, 0, 3), precision);
  setVertexFields(cloud, {"curvature"}, normalRows(normals, 4, 1), precision);
}

FitFieldWriter::FitFieldWriter(pcl::PCLPointCloud2& cloud, const std::string& output_path,
                               FieldPrecision precision, bool robust_scores)
    : cloud_(cloud),
      normal_names_(normalNames(cloud, output_path)),
      precision_(precision),
      robust_scores_(robust_scores) {}

void FitFieldWriter::write(std::size_t first, const LocalFitResult& slice) {
  if (!laid_out_) {
    // With the first slice, when the fit's search is built: its peak and the fields' memory do
    // not meet.
    addVertexFields(cloud_, normal_names_, precision_);
    addVertexFields(cloud_, {"curvature"}, precision_);
    if (robust_scores_) {
      addVertexFields(cloud_, {"scale"}, precision_);
      addVertexFields(cloud_, {"confidence"}, precision_);
    }
    laid_out_ = true;
  }
  setVertexFieldSlice(cloud_, normal_names_, first, normalRows(slice.normals, 0, 3));
  setVertexFieldSlice(cloud_, {"curvature"}, first, normalRows(slice.normals, 4, 1));
  if (!robust_scores_) return;
  const auto row = [](const std::vector<float>& values) {
    return Eigen::Map<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>(
        values.data(), 1, static_cast<Eigen::Index>(values.size()), Eigen::OuterStride<>(1));
  };
  setVertexFieldSlice(cloud_, {"scale"}, first, row(slice.scales));
  setVertexFieldSlice(cloud_, {"confidence"}, first, row(slice.confidences));
}

Eigen::Matrix3Xd normalsOf(const pcl::PointCloud<pcl::Normal>& normals) {
  Eigen::Matrix3Xd n(3, normals.size());
  for (std::size_t i = 0; i < normals.size(); ++i)
    n.col(i) = normals[i].getNormalVector3fMap().cast<double>();
  return n;
}

void setColorMapFields(const char* tool_name, pcl::PCLPointCloud2& cloud,
                       const std::string& output_path, const std::string& field_name,
                       const Eigen::VectorXd& values, const VertexColors& colors) {
  if (vertexColorLayout(cloud)) {
    warn(tool_name, "the input's own colours are replaced by the colour map of " + field_name);
  }
  setVertexColors(cloud, colors);
  if (fileExtension(output_path) == "ply" && !hasVertexField(cloud, "quality"))
    setVertexField(cloud, "quality", values);
}

FieldPrecision coordinatePrecision(FieldPrecision input, FieldPrecision requested) {
  return input == FieldPrecision::Double || requested == FieldPrecision::Double
             ? FieldPrecision::Double
             : FieldPrecision::Float;
}

namespace {

// The mesh as its x, y, z stand, through saveMesh.
void saveMeshAsItIs(const char* tool_name, const std::string& path, pcl::PolygonMesh& mesh,
                    const SensorPose& sensor_pose, const std::shared_ptr<const LasLayout>& las,
                    const std::shared_ptr<const FaceRows>& faces) {
  if (fileExtension(path) == "pcd") {
    std::string doubles;
    for (const auto& f : mesh.cloud.fields) {
      if (f.datatype == pcl::PCLPointField::FLOAT64)
        doubles += (doubles.empty() ? "" : " ") + f.name;
    }
    if (!doubles.empty()) {
      warn(tool_name, path + " gets double fields (" + doubles +
                          "), which pcl::io::loadPCDFile cannot read into PCL's float "
                          "point types (pcl::PointXYZ, pcl::Normal, ...)");
    }
  }
  Timer timer("Saving " + path);
  MeshWriteOptions options;
  options.sensor_pose = sensor_pose;
  options.las = las;
  options.faces = faces;
  saveMesh(path, mesh, options);
  timer.done(static_cast<std::size_t>(mesh.cloud.width) * mesh.cloud.height);
}

}  // namespace

void saveResult(const char* tool_name, const std::string& path, pcl::PolygonMesh& mesh,
                const Eigen::Matrix3Xd& positions, FieldPrecision coordinates,
                const SensorPose& sensor_pose, const std::shared_ptr<const LasLayout>& las,
                const std::shared_ptr<const FaceRows>& faces) {
  setVertexCoordinates(mesh.cloud, positions, coordinates);
  saveMeshAsItIs(tool_name, path, mesh, sensor_pose, las, faces);
}

void saveResult(const char* tool_name, const std::string& path, ToolInput& in,
                FieldPrecision requested) {
  const FieldPrecision coordinates = coordinatePrecision(in.coordinate_precision, requested);
  if (in.coordinatesInRows() && coordinates == FieldPrecision::Float) {
    saveMeshAsItIs(tool_name, path, in.mesh, in.sensor_pose, in.las, in.outputFaces());
    return;
  }
  saveResult(tool_name, path, in.mesh, in.positions(), coordinates, in.sensor_pose, in.las,
             in.outputFaces());
}

}  // namespace tools
}  // namespace pcl_ddg
