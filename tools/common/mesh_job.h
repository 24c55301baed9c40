#pragma once
// The shared shape of the mesh tools: load and check a surface mesh (warning about its defects),
// then save the result with its new vertex fields.
#include <pcl/PolygonMesh.h>

#include <Eigen/Core>
#include <string>

#include "common/tool_common.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/operators/mass_matrix.h"
#include "pcl_ddg/operators/sparse_cholesky.h"
#include "pcl_ddg/surface/implicit_solver.h"

namespace pcl_ddg {
namespace tools {

struct SurfaceMesh {
  pcl::PolygonMesh mesh;  ///< x, y, z as float (PCL's point types); positions holds them exactly
  MeshTopology topology;
  Eigen::Matrix3Xd positions;
  FieldPrecision coordinate_precision = FieldPrecision::Float;  ///< as the file declares them
};

/** Loads a mesh with faces; throws on out-of-range indices or non-finite coordinates, prints one
 *  warning line per kind of defect (degenerate, duplicate, non-manifold, unreferenced). */
SurfaceMesh loadSurfaceMesh(const std::string& path, const char* tool_name);

/** The checks and warnings of loadSurfaceMesh, for a file already loaded. */
SurfaceMesh checkSurfaceMesh(MeshFile file, const char* tool_name);

/** A vertex-area option (-area or -mass): mixed|voronoi|barycentric, default mixed. */
MassType massTypeArgument(const ToolArguments& args, const std::string& option);

struct SolverChoice {
  ImplicitSolver method;
  CholeskyBackend backend;
};

/** -solver auto|cholmod|ldlt|cg: auto picks the cheaper of Cholesky and conjugate gradients for
 *  the run; cholmod and ldlt factorise with that backend; cg always iterates. */
SolverChoice solverArgument(const ToolArguments& args);

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
 * types cannot read.
 */
void saveResult(const char* tool_name, const std::string& path, pcl::PolygonMesh& mesh,
                const Eigen::Matrix3Xd& positions, FieldPrecision coordinates,
                const SensorPose& sensor_pose = {},
                const std::shared_ptr<const LasLayout>& las = nullptr);

}  // namespace tools
}  // namespace pcl_ddg
