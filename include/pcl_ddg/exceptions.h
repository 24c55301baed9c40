#pragma once
// clang-format off
/** \file
 * Error policy of pcl_ddg (the README states the same table).
 *
 * | input problem                  | mesh / operator API               | estimators, searches      | tools        |
 * |--------------------------------|-----------------------------------|---------------------------|--------------|
 * | empty mesh or cloud            | throw InvalidMeshException        | PCL_ERROR, empty output   | exit 1       |
 * | NaN/Inf coordinate             | throw, naming first index + count | NaN, is_dense = false     | exit 1       |
 * | face index out of range        | throw (or drop, if asked)         | search constructor throws | exit 1       |
 * | zero-area / duplicate face     | kept, zero weight, counted        | -                         | warning      |
 * | non-manifold, isolated vertex  | handled per face, flagged         | BFS unaffected            | warning      |
 * | n-gon, boundary                | fan-triangulated, counted         | -                         | -            |
 * | bad parameter / solver failure | pcl::BadArgumentException /       | initCompute fails,        | exit 2 / 1   |
 * |                                | pcl::ComputeFailedException       | PCL_ERROR                 |              |
 *
 * `assert` guards only internal invariants that no input can reach.
 */
// clang-format on
#include <pcl/exceptions.h>

#include <string>
#include <string_view>

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

/**
 * The text of an exception for a message. pcl::PCLException's what() prefixes the description
 * with its source location, or with ": " when it has none; that prefix is left out here.
 */
inline std::string errorDescription(const std::exception& e) {
  std::string_view text = e.what();
  const auto* pcl_exception = dynamic_cast<const pcl::PCLException*>(&e);
  if (pcl_exception != nullptr && pcl_exception->getFileName() == nullptr &&
      pcl_exception->getFunctionName() == nullptr && text.substr(0, 2) == ": ") {
    text.remove_prefix(2);
  }
  return std::string(text);
}

}  // namespace pcl_ddg
