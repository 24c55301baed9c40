#pragma once
// Error policy of pcl_ddg (the README states the same table).
//
// clang-format off
// | input problem                  | mesh / operator API               | estimators, searches      | tools        |
// |--------------------------------|-----------------------------------|---------------------------|--------------|
// | empty mesh or cloud            | throw InvalidMeshException        | PCL_ERROR, empty output   | exit 1       |
// | NaN/Inf coordinate             | throw, naming first index + count | NaN, is_dense = false     | exit 1       |
// | face index out of range        | throw (or drop, if asked)         | search constructor throws | exit 1       |
// | zero-area / duplicate face     | kept, zero weight, counted        | -                         | warning      |
// | non-manifold, isolated vertex  | handled per face, flagged         | BFS unaffected            | warning      |
// | n-gon, boundary                | fan-triangulated, counted         | -                         | -            |
// | bad parameter / solver failure | pcl::BadArgumentException /       | initCompute fails,        | exit 2 / 1   |
// |                                | pcl::ComputeFailedException       | PCL_ERROR                 |              |
// clang-format on
//
// `assert` guards only internal invariants that no input can reach.
#include <pcl/exceptions.h>

#include <string>

namespace pcl_ddg {

/** A mesh or cloud that cannot be processed: empty, non-finite coordinates, bad indices. */
class InvalidMeshException : public pcl::PCLException {
 public:
  explicit InvalidMeshException(const std::string& description) : pcl::PCLException(description) {}
};

/** A file that cannot be read or written: missing, unknown format, truncated, malformed. */
class FileFormatException : public pcl::IOException {
 public:
  explicit FileFormatException(const std::string& description) : pcl::IOException(description) {}
};

}  // namespace pcl_ddg
