#pragma once
// Named per-vertex values attached to a cloud, written as PLY vertex properties (CloudCompare
// shows them as scalar fields) or PCD fields; colours as uchar red/green/blue (MeshLab).
#include <pcl/PCLPointCloud2.h>

#include <Eigen/Core>
#include <cstdint>
#include <string>

namespace pcl_ddg {

enum class FieldPrecision { Float, Double };

/** Adds the field, or replaces a field of the same name; values.size() must be the point count. */
void setVertexField(pcl::PCLPointCloud2& cloud, const std::string& name,
                    const Eigen::VectorXd& values,
                    FieldPrecision precision = FieldPrecision::Float);

/**
 * Writes positions as the x, y, z fields in the given precision: in place when they already have
 * that type, else as the first three fields of a new layout (every other field kept, in order).
 * PCL's point types read FLOAT32 coordinates only; FLOAT64 keeps far-from-origin scans exact.
 * Throws InvalidMeshException when a finite value does not fit a float.
 */
void setVertexCoordinates(pcl::PCLPointCloud2& cloud, const Eigen::Matrix3Xd& positions,
                          FieldPrecision precision);

/** Sets uchar fields red, green, blue (replacing any colour fields, packed rgb/rgba included). */
void setVertexColors(pcl::PCLPointCloud2& cloud,
                     const Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic>& rgb);

/** Removes a field if present; returns whether it was there. */
bool removeVertexField(pcl::PCLPointCloud2& cloud, const std::string& name);

}  // namespace pcl_ddg
