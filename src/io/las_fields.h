#pragma once
// What the LAS reader and writer share (private to pcl_ddg_io; defined in las_fields.cpp): the
// bytes of a little-endian file, the header's sizes and scale check, the point data record
// formats' fields, the Extra Bytes data types, scaling and names.
#include <pcl/PCLPointField.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "pcl_ddg/io/las_layout.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the LAS reader assumes a little-endian host"
#endif

namespace pcl_ddg {
namespace detail {

constexpr std::size_t kVlrHeader = 54;
constexpr std::size_t kEvlrHeader = 60;
constexpr std::size_t kDescriptorSize = 192;

/** Throws FileFormatException("LAS: " + message). */
[[noreturn]] void fail(const std::string& message);

template <typename T>
T get(const char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

template <typename T>
void put(char* p, T value) {
  std::memcpy(p, &value, sizeof(T));
}

/** The public header block's size in LAS 1.minor (227, 235 or 375 bytes). */
std::size_t headerSizeOf(int minor);

/** bytes up to their first NUL. */
std::string upToNul(const std::string& bytes);

/** Whether doubles resolve every step of the axis's integer grid (las_fields.cpp). */
bool gridResolvable(double scale, double offset);
/** fail() unless every axis's scale is finite and non-zero, its offset finite and the grid
 *  resolvable. */
void requireScale(const Eigen::Vector3d& scale, const Eigen::Vector3d& offset);

// One field of a point data record format: whole bytes (copied as they are) or bits of a byte.
struct CoreField {
  const char* name;
  std::uint8_t datatype;             ///< the cloud field's pcl::PCLPointField type
  std::uint16_t offset;              ///< in the record
  std::uint8_t shift = 0, bits = 0;  ///< bits > 0: a bit field of the byte at offset
};

using F = pcl::PCLPointField;

/** The fields of point data record format `format` (0-10) beyond x, y, z, in record order. */
std::vector<CoreField> coreFields(int format);

// --- Extra Bytes descriptors ---------------------------------------------------------------

// The pcl type and element count of an Extra Bytes data type (1-10 scalars, 11-30 the deprecated
// 2- and 3-arrays); type 0 is `options` undocumented bytes.
struct ExtraType {
  std::uint8_t datatype;
  std::uint32_t count;
};

/** The Extra Bytes data type (1-10) of a cloud field's type, 0 for one it has none for. */
int lasTypeOfPcl(std::uint8_t datatype);
/** The type of a 192-byte descriptor (the index-th, for the message); fail() for an unknown one. */
ExtraType extraType(const char* descriptor, std::size_t index);
std::uint32_t byteSize(const ExtraType& t);

// A dimension whose descriptor sets a scale or an offset (options bits 3 and 4) holds raw values:
// the value is raw * scale + offset (1 and 0 when unset), a double, per element. Applied to
// integers of up to 32 bits where doubles resolve every step (as for the coordinates: so that
// writing (value - offset) / scale gives the raw integer back); other such dimensions stay raw,
// their descriptor kept.
struct ExtraScaling {
  bool scaled = false;
  double scale[3] = {1.0, 1.0, 1.0}, offset[3] = {0.0, 0.0, 0.0};
};

/** The scaling of a descriptor (scaled = false: the raw values are kept). */
ExtraScaling extraScaling(const std::string& descriptor);

/** The cloud field name of an Extra Bytes dimension named las_name (the index-th), and back. */
std::string cloudNameOf(const std::string& las_name, std::size_t index);
std::string lasNameOf(const std::string& field);
/** The Extra Bytes VLR: user "LASF_Spec", record 4. */
bool isExtraBytesRecord(const LasVariableLengthRecord& r);

}  // namespace detail
}  // namespace pcl_ddg
