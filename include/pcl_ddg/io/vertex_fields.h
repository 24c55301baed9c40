#pragma once
/** \file
 * Named per-vertex values attached to a cloud, written as PLY vertex properties (CloudCompare
 * shows them as scalar fields) or PCD fields; colours as uchar red/green/blue (MeshLab).
 */
#include <pcl/PCLPointCloud2.h>

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pcl_ddg {

enum class FieldPrecision { Float, Double };

/** Adds the field, or replaces a field of the same name; values.size() must be the point count. */
void setVertexField(pcl::PCLPointCloud2& cloud, const std::string& name,
                    const Eigen::VectorXd& values,
                    FieldPrecision precision = FieldPrecision::Float);

/** setVertexField for several fields at once, row r of `values` (one column per vertex) as
 *  names[r]: the cloud is laid out anew once, not once per field. The rows are widened in place
 *  when cloud.data's capacity holds them (readMeshFile's spare bytes per point), so that adding
 *  fields to a large cloud does not hold it twice. */
void setVertexFields(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                     const Eigen::Ref<const Eigen::MatrixXd>& values,
                     FieldPrecision precision = FieldPrecision::Float);
/** The same of float values where they lie, e.g. the normals of a pcl::PointCloud<pcl::Normal>
 *  (a map of its floats with an outer stride of 8); `values` must not lie in cloud.data, which
 *  the new layout rewrites. */
void setVertexFields(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                     const Eigen::Ref<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>& values,
                     FieldPrecision precision = FieldPrecision::Float);

/** Lays out the fields `names` (replacing any of the same names), NaN until setVertexFieldSlice
 *  writes them: a result that comes a slice of points at a time is written where it belongs and
 *  never held whole beside the cloud. In place within cloud.data's capacity, as setVertexFields. */
void addVertexFields(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                     FieldPrecision precision = FieldPrecision::Float);
/** Writes row r of `values` into field names[r] (FLOAT32 or FLOAT64, one value a point) of points
 *  first .. first + values.cols() - 1; throws pcl::BadArgumentException for a missing field or
 *  points beyond the cloud's. */
void setVertexFieldSlice(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                         std::size_t first,
                         const Eigen::Ref<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>& values);

/**
 * Writes positions as the x, y, z fields in the given precision: in place when they already have
 * that type, else as the first three fields of a new layout (every other field kept, in order).
 * PCL's point types read FLOAT32 coordinates only; FLOAT64 keeps far-from-origin scans exact.
 * Throws InvalidMeshException when a finite value does not fit a float.
 */
void setVertexCoordinates(pcl::PCLPointCloud2& cloud, const Eigen::Matrix3Xd& positions,
                          FieldPrecision precision);

using VertexColors = Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic>;

/** How a format keeps colours: PLY as uchar red, green, blue (MeshLab, CloudCompare); PCD as one
 *  packed float `rgb` (0xAARRGGBB, PCL's PointXYZRGB, what pcl_viewer's colour handler reads). */
enum class ColorLayout { Channels, PackedRGB };

/** Sets the colours in the given layout, replacing any colour fields (red green blue alpha, packed
 *  rgb or rgba). */
void setVertexColors(pcl::PCLPointCloud2& cloud, const VertexColors& rgb,
                     ColorLayout layout = ColorLayout::Channels);

/** The layout of the cloud's colours: red, green, blue fields or a packed rgb/rgba; none if it
 *  has neither. */
std::optional<ColorLayout> vertexColorLayout(const pcl::PCLPointCloud2& cloud);

/** The cloud's colours from either layout; throws InvalidMeshException if it has none. */
VertexColors vertexColors(const pcl::PCLPointCloud2& cloud);

/** Removes a field if present; returns whether it was there. */
bool removeVertexField(pcl::PCLPointCloud2& cloud, const std::string& name);

}  // namespace pcl_ddg
