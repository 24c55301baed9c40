#include "common/mesh_job.h"

#include <iostream>

#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace tools {

SurfaceMesh loadSurfaceMesh(const std::string& path, const char* tool_name) {
  Timer timer("Loading " + path);
  MeshFile file = readMeshFile(path);
  if (file.mesh.polygons.empty()) throw std::runtime_error(path + " has no faces (a point cloud?)");
  timer.done(static_cast<std::size_t>(file.positions.cols()));
  return checkSurfaceMesh(std::move(file), tool_name);
}

SurfaceMesh checkSurfaceMesh(MeshFile file, const char* tool_name) {
  Timer timer("Building the mesh topology");
  requireFinite(file.positions);
  MeshTopology topology(file.mesh);
  Eigen::Matrix3Xd& positions = file.positions;
  // Only the defects worth a warning (pcl_ddg_info makes the whole MeshReport).
  const TopologyCounts& counts = topology.counts();
  const std::int64_t degenerate =
      counts.repeated_index_polygons + countZeroAreaFaces(topology, positions);
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
  return {std::move(file.mesh), std::move(topology), std::move(positions),
          file.coordinate_precision};
}

MassType massTypeArgument(const ToolArguments& args, const std::string& option) {
  const std::string area = args.choice(option, {"mixed", "voronoi", "barycentric"}, "mixed");
  return area == "voronoi"       ? MassType::Voronoi
         : area == "barycentric" ? MassType::Barycentric
                                 : MassType::MixedVoronoi;
}

SolverChoice solverArgument(const ToolArguments& args) {
  const std::string solver = args.choice("solver", {"auto", "cholmod", "ldlt", "cg"}, "auto");
  if (solver == "cholmod") return {ImplicitSolver::Cholesky, CholeskyBackend::Cholmod};
  if (solver == "ldlt") return {ImplicitSolver::Cholesky, CholeskyBackend::SimplicialLDLT};
  if (solver == "cg") return {ImplicitSolver::ConjugateGradient, CholeskyBackend::Automatic};
  return {ImplicitSolver::Automatic, CholeskyBackend::Automatic};
}

FieldPrecision precisionArgument(const ToolArguments& args) {
  return args.choice("precision", {"float", "double"}, "float") == "double" ? FieldPrecision::Double
                                                                            : FieldPrecision::Float;
}

void setNormalTriple(pcl::PCLPointCloud2& cloud, const std::string& output_path,
                     const Eigen::Matrix3Xd& normals, FieldPrecision precision) {
  const char* ply_names[] = {"nx", "ny", "nz"};
  const char* pcd_names[] = {"normal_x", "normal_y", "normal_z"};
  const bool pcd_naming = hasVertexField(cloud, "normal_x") ? true
                          : hasVertexField(cloud, "nx")     ? false
                                                            : fileExtension(output_path) == "pcd" ||
                                                              fileExtension(output_path) == "las";
  for (int d = 0; d < 3; ++d) removeVertexField(cloud, pcd_naming ? ply_names[d] : pcd_names[d]);
  const char** names = pcd_naming ? pcd_names : ply_names;
  setVertexFields(cloud, {names[0], names[1], names[2]}, normals, precision);
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

void saveResult(const char* tool_name, const std::string& path, pcl::PolygonMesh& mesh,
                const Eigen::Matrix3Xd& positions, FieldPrecision coordinates,
                const SensorPose& sensor_pose, const std::shared_ptr<const LasLayout>& las) {
  setVertexCoordinates(mesh.cloud, positions, coordinates);
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
  saveMesh(path, mesh, options);
  timer.done(static_cast<std::size_t>(mesh.cloud.width) * mesh.cloud.height);
}

}  // namespace tools
}  // namespace pcl_ddg
