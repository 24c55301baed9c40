#pragma once
// The steps of writing LAS records by a plan (private to pcl_ddg_io; defined in las_write.cpp):
// encoding points into records, the header with the records' bounds and counts, and the blocks
// of a cloud. writeLAS and the out-of-core LasPieceWriter are made of them.
#include <pcl/PCLPointCloud2.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include "las_plan.h"
#include "pcl_ddg/io/vertex_fields.h"

namespace pcl_ddg {
namespace detail {

// What the header says of the records: integer bounds and counts by return.
struct RecordStats {
  static constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  std::array<std::int64_t, 3> lo{kMax, kMax, kMax}, hi{-kMax, -kMax, -kMax};
  bool any = false;
  std::array<std::uint64_t, 15> by_return{};

  void add(const RecordStats& other) {
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], other.lo[d]);
      hi[d] = std::max(hi[d], other.hi[d]);
    }
    any = any || other.any;
    for (std::size_t r = 0; r < by_return.size(); ++r) by_return[r] += other.by_return[r];
  }
};

/** Records [first, first + positions.cols()) into `records` (zeroed); throws for the first point
 *  LAS cannot hold. */
void encodeRecords(const LasPlan& plan, const pcl::PCLPointCloud2& cloud, std::size_t first,
                   const Eigen::Matrix3Xd& positions, const VertexColors& colors, char* records,
                   RecordStats& stats);

/** Where the file's parts go: bytes at an offset. */
using ByteSink = std::function<void(std::uint64_t at, const char* bytes, std::size_t size)>;

/** Writes the header, VLRs and EVLRs of a file of n records with these stats (the records
 *  themselves are written by the caller). */
void writeHeaderAndRecords(const LasPlan& plan, std::size_t n, const RecordStats& stats,
                           const ByteSink& sink);

// Points encoded at once by writeLAS: a few MB of records, reused.
constexpr std::size_t kBlockPoints = 1 << 18;

/** The rows [first, first + count) of cloud as a cloud of their own. */
pcl::PCLPointCloud2 rowsOf(const pcl::PCLPointCloud2& cloud, std::size_t first, std::size_t count);

/** The exact coordinates of rows [first, first + count): read in place from float or double
 *  fields, through a copy of the rows for any other type. */
Eigen::Matrix3Xd blockPositions(const pcl::PCLPointCloud2& cloud, std::size_t first,
                                std::size_t count);

/** bytes at `at` of fd (the file at path), all written; FileFormatException if they cannot be. */
void pwriteAll(int fd, const std::string& path, std::uint64_t at, const char* bytes,
               std::size_t size);

}  // namespace detail
}  // namespace pcl_ddg
