#pragma once
/** \file
 * Polygons as MeshTopology reads them: PCL's `std::vector<pcl::Vertices>`, a heap vector per face,
 * or rows of a fixed number of corners in one flat array (a 3 x T triangle matrix, a NumPy face
 * array, the rows the readers fill for the tools), which need no allocation per face: the 2.3M
 * triangles of the bench torus take 28 MB as rows and about 120 MB as pcl::Vertices.
 */
#include <pcl/Vertices.h>
#include <pcl/types.h>

#include <cstddef>
#include <vector>

namespace pcl_ddg {

/** The corners of one polygon (a view into the list's storage). */
struct PolygonCorners {
  const pcl::index_t* first = nullptr;
  std::size_t count = 0;
  std::size_t size() const { return count; }
  pcl::index_t operator[](std::size_t k) const { return first[k]; }
  const pcl::index_t* begin() const { return first; }
  const pcl::index_t* end() const { return first + count; }
};

/** A view of polygons, in one of the two layouts above; the storage must outlive it. */
class PolygonList {
 public:
  PolygonList(const std::vector<pcl::Vertices>& polygons)  // NOLINT: implicit on purpose
      : polygons_(&polygons) {}
  /** rows polygons of corners corners each, row-major in indices. */
  PolygonList(const pcl::index_t* indices, std::size_t rows, std::size_t corners)
      : indices_(indices), rows_(rows), corners_(corners) {}

  std::size_t size() const { return polygons_ ? polygons_->size() : rows_; }
  PolygonCorners operator[](std::size_t i) const {
    if (polygons_) {
      const pcl::Indices& corners = (*polygons_)[i].vertices;
      return {corners.data(), corners.size()};
    }
    return {indices_ + i * corners_, corners_};
  }

 private:
  const std::vector<pcl::Vertices>* polygons_ = nullptr;
  const pcl::index_t* indices_ = nullptr;
  std::size_t rows_ = 0, corners_ = 0;
};

}  // namespace pcl_ddg
