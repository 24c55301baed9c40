#pragma once
// How a cloud's points become LAS records (private to pcl_ddg_io): the plan (the layout to write
// and where each of the cloud's fields goes in a record), made by planLAS (las_plan.cpp) and
// followed by the writers (las_write.cpp, las_piece_writer.cpp).
#include <pcl/PCLPointCloud2.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "las_fields.h"
#include "pcl_ddg/io/las_layout.h"

namespace pcl_ddg {
namespace detail {

struct ByteCopy {
  std::uint32_t from, to, size;
};
struct ScaledSlot {  // doubles of the cloud stored as (value - offset) / scale in raw_type
  const pcl::PCLPointField* field;
  std::uint32_t to;
  std::uint8_t raw_type;
  std::uint32_t count;
  ExtraScaling scaling;
};
struct BitSlot {
  const pcl::PCLPointField* field;  ///< null: the default value
  std::uint32_t to;
  std::uint8_t shift, bits, fallback;
  bool is_return_number;
};

// How a cloud's points become records: the layout to write and where each field goes.
struct LasPlan {
  LasLayout layout;
  int format = 0;
  bool extended = false;
  std::vector<ByteCopy> copies;              // bytes of the cloud's rows copied as they are
  std::vector<BitSlot> bit_slots;            // the format's bit fields
  const pcl::PCLPointField* rank = nullptr;  // scan angle of the other kind (degrees <-> steps)
  std::uint32_t angle_to = 0;
  bool convert_colors = false;  // colours of another layout into 16-bit RGB at rgb_to
  std::uint32_t rgb_to = 0;
  std::vector<ScaledSlot> scaled;  // Extra Bytes with a scale or offset
  std::uint64_t record_length = 0;
  std::size_t standard = 0;  // the public header block's size for the version
  std::uint64_t header_size = 0, point_offset = 0;
};

/** A record of the source's encoding, which a file written from it does not carry: a COPC file's
 *  info VLR and hierarchy EVLR (user id "copc": the records no longer follow its octree) and a
 *  LASzip VLR (22204; an uncompressed file carrying one would be read as LAZ by some readers, and
 *  a LAZ output gets its own). */
bool isEncodingRecord(const LasVariableLengthRecord& record);

/** The plan for writing cloud: source's layout, or LAS 1.4 format 6/7 whose scale and offset are
 *  chosen from finite_bounds() (called only then). */
LasPlan planLAS(const pcl::PCLPointCloud2& cloud, const LasLayout* source,
                const std::function<Eigen::AlignedBox3d()>& finite_bounds);

/** The cloud's field of that name, null if it has none. */
const pcl::PCLPointField* findField(const pcl::PCLPointCloud2& cloud, const std::string& name);
/** text cut or padded with NULs to size bytes. */
std::string padded(const std::string& text, std::size_t size);

}  // namespace detail
}  // namespace pcl_ddg
