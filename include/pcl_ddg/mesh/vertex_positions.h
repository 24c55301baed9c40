#pragma once
/** \file
 * Vertex coordinates between PCL clouds (float or double fields) and Eigen (double, 3 x N).
 */
#include <pcl/PCLPointCloud2.h>

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "pcl_ddg/mesh/positions_ref.h"

namespace pcl_ddg {

/** What to do with a vertex whose coordinates are NaN or infinite. */
enum class NonFinitePolicy { Throw, Keep };

/** The first non-finite vertex (-1 if none) and how many there are. */
struct NonFiniteVertices {
  std::int64_t first = -1;
  std::int64_t count = 0;
};

NonFiniteVertices findNonFiniteVertices(const PositionsRef& positions);

/**
 * Reads the x, y, z fields (any numeric type) of every point into a 3 x N matrix in double.
 * Throws InvalidMeshException if the cloud lacks x/y/z or, with NonFinitePolicy::Throw, if a
 * coordinate is NaN or infinite (naming the first such vertex and the count).
 */
Eigen::Matrix3Xd vertexPositions(const pcl::PCLPointCloud2& cloud,
                                 NonFinitePolicy policy = NonFinitePolicy::Throw);

/**
 * Writes positions into the cloud's existing x, y, z fields (float or double, kept as they are:
 * a float mesh stays float). Throws InvalidMeshException on a size mismatch or integer fields,
 * and when a finite value does not fit a float field (it would become infinite).
 */
void setVertexPositions(pcl::PCLPointCloud2& cloud, const Eigen::Matrix3Xd& positions);

/** One numeric field of every point, in double; throws InvalidMeshException if it is missing. */
Eigen::VectorXd vertexScalarField(const pcl::PCLPointCloud2& cloud, const std::string& name);

/** True if the cloud has a field of that name. */
bool hasVertexField(const pcl::PCLPointCloud2& cloud, const std::string& name);

/** value as a float for a float field; throws InvalidMeshException naming the field and the
 *  vertex when a finite value lies beyond float's range (the cast would be undefined). */
float floatFieldValue(double value, const std::string& field, std::size_t vertex);

/** Throws InvalidMeshException naming the first non-finite vertex and the count, if any. */
void requireFinite(const PositionsRef& positions);

}  // namespace pcl_ddg
