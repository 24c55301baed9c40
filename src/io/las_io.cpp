// ASPRS LAS 1.0-1.4, uncompressed, point data record formats 0-10 (LAS 1.4 R15): read into a
// cloud whose fields are the records' fields, and written back from such a cloud. No LAS library
// is packaged in Debian 12, so the layout is implemented here, every size checked against the
// bytes the file holds before anything is allocated.
//
// A file is: the public header block (227 bytes in 1.0-1.2, 235 in 1.3, 375 in 1.4), the
// variable-length records (54-byte header + up to 65,535 bytes each), the point records (fixed
// size, the format's fields then any extra bytes), and in 1.3/1.4 extended VLRs (60-byte header,
// 64-bit length) after the points. Everything is little-endian. A coordinate is the record's
// 32-bit integer X times the header's scale plus its offset, computed in double.
#include <fcntl.h>
#include <pcl/common/io.h>
#include <sys/mman.h>

#include <unistd.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <functional>
#include <limits>
#include <sstream>

#include "formats.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/las_layout.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/vertex_positions.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the LAS reader assumes a little-endian host"
#endif

namespace pcl_ddg {

std::uint16_t lasPointFormatSize(int point_format) {
  static constexpr std::uint16_t kSizes[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  return point_format >= 0 && point_format <= 10 ? kSizes[point_format] : 0;
}

namespace {

std::string upToNul(const std::string& bytes) {
  return bytes.substr(0, bytes.find('\0'));
}

}  // namespace

std::string LasVariableLengthRecord::userId() const {
  return upToNul(user_id);
}

std::string LasVariableLengthRecord::descriptionText() const {
  return upToNul(description);
}

namespace detail {
namespace {

constexpr std::size_t kVlrHeader = 54;
constexpr std::size_t kEvlrHeader = 60;
constexpr std::size_t kDescriptorSize = 192;

[[noreturn]] void fail(const std::string& message) {
  throw FileFormatException("LAS: " + message);
}

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

std::size_t headerSizeOf(int minor) {
  return minor >= 4 ? 375 : minor == 3 ? 235 : 227;
}

// One field of a point data record format: whole bytes (copied as they are) or bits of a byte.
struct CoreField {
  const char* name;
  std::uint8_t datatype;             ///< the cloud field's pcl::PCLPointField type
  std::uint16_t offset;              ///< in the record
  std::uint8_t shift = 0, bits = 0;  ///< bits > 0: a bit field of the byte at offset
};

using F = pcl::PCLPointField;

std::vector<CoreField> coreFields(int format) {
  std::vector<CoreField> fields = {{"intensity", F::UINT16, 12}};
  const bool extended = format >= 6;
  if (!extended) {
    fields.insert(fields.end(), {{"return_number", F::UINT8, 14, 0, 3},
                                 {"number_of_returns", F::UINT8, 14, 3, 3},
                                 {"scan_direction_flag", F::UINT8, 14, 6, 1},
                                 {"edge_of_flight_line", F::UINT8, 14, 7, 1},
                                 {"classification", F::UINT8, 15, 0, 5},
                                 {"classification_flags", F::UINT8, 15, 5, 3},
                                 {"scan_angle_rank", F::INT8, 16},
                                 {"user_data", F::UINT8, 17},
                                 {"point_source_id", F::UINT16, 18}});
  } else {
    fields.insert(fields.end(), {{"return_number", F::UINT8, 14, 0, 4},
                                 {"number_of_returns", F::UINT8, 14, 4, 4},
                                 {"classification_flags", F::UINT8, 15, 0, 4},
                                 {"scanner_channel", F::UINT8, 15, 4, 2},
                                 {"scan_direction_flag", F::UINT8, 15, 6, 1},
                                 {"edge_of_flight_line", F::UINT8, 15, 7, 1},
                                 {"classification", F::UINT8, 16},
                                 {"user_data", F::UINT8, 17},
                                 {"scan_angle", F::INT16, 18},
                                 {"point_source_id", F::UINT16, 20},
                                 {"gps_time", F::FLOAT64, 22}});
  }
  if (format == 1 || format == 3 || format == 4 || format == 5)
    fields.push_back({"gps_time", F::FLOAT64, 20});
  int rgb = -1, nir = -1, wave = -1;
  switch (format) {
    case 2:
      rgb = 20;
      break;
    case 3:
      rgb = 28;
      break;
    case 4:
      wave = 28;
      break;
    case 5:
      rgb = 28;
      wave = 34;
      break;
    case 7:
      rgb = 30;
      break;
    case 8:
      rgb = 30;
      nir = 36;
      break;
    case 9:
      wave = 30;
      break;
    case 10:
      rgb = 30;
      nir = 36;
      wave = 38;
      break;
    default:
      break;
  }
  if (rgb >= 0) {
    const auto o = static_cast<std::uint16_t>(rgb);
    fields.insert(fields.end(), {{"red", F::UINT16, o},
                                 {"green", F::UINT16, static_cast<std::uint16_t>(o + 2)},
                                 {"blue", F::UINT16, static_cast<std::uint16_t>(o + 4)}});
  }
  if (nir >= 0) fields.push_back({"nir", F::UINT16, static_cast<std::uint16_t>(nir)});
  if (wave >= 0) {
    const auto o = static_cast<std::uint16_t>(wave);
    const auto at = [o](int k) { return static_cast<std::uint16_t>(o + k); };
    fields.insert(fields.end(), {{"wave_packet_index", F::UINT8, o},
                                 {"wave_packet_offset", F::UINT64, at(1)},
                                 {"wave_packet_size", F::UINT32, at(9)},
                                 {"wave_return_location", F::FLOAT32, at(13)},
                                 {"wave_x_t", F::FLOAT32, at(17)},
                                 {"wave_y_t", F::FLOAT32, at(21)},
                                 {"wave_z_t", F::FLOAT32, at(25)}});
  }
  return fields;
}

// --- Extra Bytes descriptors ---------------------------------------------------------------

// The pcl type and element count of an Extra Bytes data type (1-10 scalars, 11-30 the deprecated
// 2- and 3-arrays); type 0 is `options` undocumented bytes.
struct ExtraType {
  std::uint8_t datatype;
  std::uint32_t count;
};

std::uint8_t pclTypeOfLas(int base) {
  static constexpr std::uint8_t kTypes[] = {F::UINT8, F::INT8,   F::UINT16, F::INT16,   F::UINT32,
                                            F::INT32, F::UINT64, F::INT64,  F::FLOAT32, F::FLOAT64};
  return kTypes[base - 1];
}

int lasTypeOfPcl(std::uint8_t datatype) {
  switch (datatype) {
    case F::UINT8:
      return 1;
    case F::INT8:
      return 2;
    case F::UINT16:
      return 3;
    case F::INT16:
      return 4;
    case F::UINT32:
      return 5;
    case F::INT32:
      return 6;
    case F::UINT64:
      return 7;
    case F::INT64:
      return 8;
    case F::FLOAT32:
      return 9;
    case F::FLOAT64:
      return 10;
    default:
      return 0;
  }
}

ExtraType extraType(const char* descriptor, std::size_t index) {
  const int type = static_cast<std::uint8_t>(descriptor[2]);
  const int options = static_cast<std::uint8_t>(descriptor[3]);
  if (type == 0) {
    if (options == 0)
      fail("Extra Bytes dimension " + std::to_string(index) +
           " is of type 0 (undocumented bytes) with no size in its options");
    return {F::UINT8, static_cast<std::uint32_t>(options)};
  }
  if (type > 30)
    fail("Extra Bytes dimension " + std::to_string(index) + " has unknown data type " +
         std::to_string(type));
  const int base = (type - 1) % 10 + 1;
  return {pclTypeOfLas(base), static_cast<std::uint32_t>((type - 1) / 10 + 1)};
}

std::uint32_t byteSize(const ExtraType& t) {
  return pcl::getFieldSize(t.datatype) * t.count;
}

// A dimension whose descriptor sets a scale or an offset (options bits 3 and 4) holds raw values:
// the value is raw * scale + offset (1 and 0 when unset), a double, per element. Applied to
// integers of up to 32 bits where doubles resolve every step (as for the coordinates: so that
// writing (value - offset) / scale gives the raw integer back); other such dimensions stay raw,
// their descriptor kept.
struct ExtraScaling {
  bool scaled = false;
  double scale[3] = {1.0, 1.0, 1.0}, offset[3] = {0.0, 0.0, 0.0};
};

ExtraScaling extraScaling(const std::string& descriptor) {
  ExtraScaling s;
  const int type = static_cast<std::uint8_t>(descriptor[2]);
  const int options = static_cast<std::uint8_t>(descriptor[3]);
  if (type == 0 || type > 30 || (options & 0x18) == 0) return s;
  const int base = (type - 1) % 10 + 1;  // 1-6: 8 to 32-bit integers
  if (base > 6) return s;
  for (int j = 0; j < (type - 1) / 10 + 1; ++j) {  // the dimension's elements only
    if (options & 0x08) s.scale[j] = get<double>(descriptor.data() + 112 + 8 * j);
    if (options & 0x10) s.offset[j] = get<double>(descriptor.data() + 136 + 8 * j);
    const double largest = std::abs(s.offset[j]) + std::abs(s.scale[j]) * 4294967296.0;
    const double spacing =
        std::nextafter(largest, std::numeric_limits<double>::infinity()) - largest;
    if (!std::isfinite(s.scale[j]) || s.scale[j] == 0.0 || !std::isfinite(s.offset[j]) ||
        !(spacing <= std::abs(s.scale[j]) / 8.0))
      return ExtraScaling();
  }
  s.scaled = true;
  return s;
}

double rawValue(const char* p, std::uint8_t datatype) {
  switch (datatype) {
    case F::UINT8:
      return get<std::uint8_t>(p);
    case F::INT8:
      return get<std::int8_t>(p);
    case F::UINT16:
      return get<std::uint16_t>(p);
    case F::INT16:
      return get<std::int16_t>(p);
    case F::UINT32:
      return get<std::uint32_t>(p);
    case F::INT32:
      return get<std::int32_t>(p);
    case F::UINT64:
      return static_cast<double>(get<std::uint64_t>(p));
    case F::INT64:
      return static_cast<double>(get<std::int64_t>(p));
    case F::FLOAT32:
      return get<float>(p);
    default:
      return get<double>(p);
  }
}

/** Stores value (already unscaled) in the raw type: integers rounded, within their range. */
bool putRawValue(char* p, std::uint8_t datatype, double value) {
  const auto integer = [&](auto type_tag, double lo, double hi) {
    using T = decltype(type_tag);
    const double r = std::round(value);
    if (!(r >= lo && r <= hi)) return false;
    put(p, static_cast<T>(r));
    return true;
  };
  switch (datatype) {
    case F::UINT8:
      return integer(std::uint8_t{}, 0, 255);
    case F::INT8:
      return integer(std::int8_t{}, -128, 127);
    case F::UINT16:
      return integer(std::uint16_t{}, 0, 65535);
    case F::INT16:
      return integer(std::int16_t{}, -32768, 32767);
    case F::UINT32:
      return integer(std::uint32_t{}, 0, 4294967295.0);
    case F::INT32:
      return integer(std::int32_t{}, -2147483648.0, 2147483647.0);
    case F::UINT64:  // the doubles that convert exactly
      return integer(std::uint64_t{}, 0, 18446744073709549568.0);
    case F::INT64:
      return integer(std::int64_t{}, -9223372036854775808.0, 9223372036854774784.0);
    case F::FLOAT32:
      if (std::isfinite(value) && std::abs(value) > std::numeric_limits<float>::max()) return false;
      put(p, static_cast<float>(value));
      return true;
    default:
      put(p, value);
      return true;
  }
}

// PDAL's names for normals and curvature in LAS (extra bytes) and ours in clouds (PCD naming).
const std::pair<const char*, const char*> kRenamed[] = {{"NormalX", "normal_x"},
                                                        {"NormalY", "normal_y"},
                                                        {"NormalZ", "normal_z"},
                                                        {"Curvature", "curvature"}};

std::string cloudNameOf(const std::string& las_name, std::size_t index) {
  for (const auto& [las, cloud] : kRenamed) {
    if (las_name == las) return cloud;
  }
  std::string name;
  for (const char c : las_name) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    name += plain ? c : '_';
  }
  // ("_" alone is PCL's padding, which writers skip.)
  if (name.find_first_not_of('_') == std::string::npos) return "extra_" + std::to_string(index);
  return name;
}

std::string lasNameOf(const std::string& field) {
  for (const auto& [las, cloud] : kRenamed) {
    if (field == cloud) return las;
  }
  if (field == "nx") return "NormalX";
  if (field == "ny") return "NormalY";
  if (field == "nz") return "NormalZ";
  return field;
}

bool isExtraBytesRecord(const LasVariableLengthRecord& r) {
  return r.userId() == "LASF_Spec" && r.record_id == 4;
}

// --- reading --------------------------------------------------------------------------------

struct HeaderFacts {
  std::uint64_t header_size = 0, point_offset = 0, vlr_count = 0, points = 0;
  std::uint64_t evlr_start = 0, evlr_count = 0, waveform_start = 0;
};

void readRecords(std::string_view data, std::uint64_t begin, std::uint64_t end, std::uint64_t count,
                 bool extended, std::vector<LasVariableLengthRecord>& out) {
  const char* what = extended ? "EVLR" : "VLR";
  const std::size_t head = extended ? kEvlrHeader : kVlrHeader;
  std::uint64_t at = begin;
  for (std::uint64_t i = 0; i < count; ++i) {
    if (end < head || at > end - head)
      fail(std::string(what) + " " + std::to_string(i) + " (at byte " + std::to_string(at) +
           ") runs past " + (extended ? "the end of the file" : "the start of the points") +
           " (byte " + std::to_string(end) + "); the header claims " + std::to_string(count));
    const char* p = data.data() + at;
    LasVariableLengthRecord r;
    r.reserved = get<std::uint16_t>(p);
    r.user_id.assign(p + 2, 16);
    r.record_id = get<std::uint16_t>(p + 18);
    const std::uint64_t length = extended ? get<std::uint64_t>(p + 20) : get<std::uint16_t>(p + 20);
    r.description.assign(p + (extended ? 28 : 22), 32);
    at += head;
    if (length > end - at)
      fail(std::string(what) + " " + std::to_string(i) + " ('" + r.userId() + "' " +
           std::to_string(r.record_id) + ") claims " + std::to_string(length) +
           " bytes, past byte " + std::to_string(end));
    r.data.assign(data.data() + at, static_cast<std::size_t>(length));
    at += length;
    out.push_back(std::move(r));
  }
  if (!extended && at < end) {
    // (bytes between the VLRs and the points: kept by the caller)
  }
}

// Whether doubles resolve every step of the axis's integer grid: x = X * scale + offset must give
// X back (round((x - offset) / scale)) for every 32-bit X, which needs the spacing of doubles near
// the largest |x| well below the scale.
bool gridResolvable(double scale, double offset) {
  const double largest = std::abs(offset) + std::abs(scale) * 2147483648.0;
  const double spacing = std::nextafter(largest, std::numeric_limits<double>::infinity()) - largest;
  return spacing <= std::abs(scale) / 8.0;
}

void requireScale(const Eigen::Vector3d& scale, const Eigen::Vector3d& offset) {
  for (int d = 0; d < 3; ++d) {
    const char axis = static_cast<char>('x' + d);
    if (!std::isfinite(scale[d]) || scale[d] == 0.0) {
      std::ostringstream text;
      text << axis << " scale factor " << scale[d] << " is not a finite non-zero number";
      fail(text.str());
    }
    if (!std::isfinite(offset[d])) {
      std::ostringstream text;
      text << axis << " offset " << offset[d] << " is not finite";
      fail(text.str());
    }
    if (!gridResolvable(scale[d], offset[d])) {
      std::ostringstream text;
      text << axis << " scale factor " << scale[d] << " is finer than doubles resolve at offset "
           << offset[d] << " (the coordinates could not be exact)";
      fail(text.str());
    }
  }
}

// The header, VLRs and EVLRs; the points' place is checked against the file's size.
LasLayout parseLayout(std::string_view data, HeaderFacts& facts) {
  const std::uint64_t size = data.size();
  if (size < 4 || data.substr(0, 4) != "LASF") fail("not a LAS file (no LASF signature)");
  // LAZ first: nothing else of a compressed file is worth reading.
  if (size > 104 && (static_cast<std::uint8_t>(data[104]) & 0xC0) != 0) {
    throw FileFormatException(
        "LAZ (compressed LAS) is not supported: decompress it first with "
        "`laszip -i in.laz -o out.las` or `pdal translate in.laz out.las`");
  }
  if (size < 227) fail("the file (" + std::to_string(size) + " bytes) is shorter than a header");
  LasLayout layout;
  const char* h = data.data();
  layout.file_source_id = get<std::uint16_t>(h + 4);
  layout.global_encoding = get<std::uint16_t>(h + 6);
  layout.project_id.assign(h + 8, 16);
  layout.version_major = static_cast<std::uint8_t>(h[24]);
  layout.version_minor = static_cast<std::uint8_t>(h[25]);
  if (layout.version_major != 1 || layout.version_minor > 4)
    fail("unsupported version " + std::to_string(layout.version_major) + "." +
         std::to_string(layout.version_minor) + " (1.0 to 1.4 are read)");
  layout.system_identifier.assign(h + 26, 32);
  layout.generating_software.assign(h + 58, 32);
  layout.creation_day = get<std::uint16_t>(h + 90);
  layout.creation_year = get<std::uint16_t>(h + 92);
  facts.header_size = get<std::uint16_t>(h + 94);
  facts.point_offset = get<std::uint32_t>(h + 96);
  facts.vlr_count = get<std::uint32_t>(h + 100);
  layout.point_format = static_cast<std::uint8_t>(h[104]);
  layout.record_length = get<std::uint16_t>(h + 105);
  const std::uint64_t legacy_points = get<std::uint32_t>(h + 107);
  for (int d = 0; d < 3; ++d) {
    layout.scale[d] = get<double>(h + 131 + 8 * d);
    layout.offset[d] = get<double>(h + 155 + 8 * d);
    layout.max[d] = get<double>(h + 179 + 16 * d);
    layout.min[d] = get<double>(h + 187 + 16 * d);
  }
  const std::size_t standard = headerSizeOf(layout.version_minor);
  if (facts.header_size < standard)
    fail("header size " + std::to_string(facts.header_size) + " is smaller than LAS 1." +
         std::to_string(layout.version_minor) + "'s " + std::to_string(standard) + " bytes");
  if (facts.header_size > size)
    fail("header size " + std::to_string(facts.header_size) + " is past the end of the file (" +
         std::to_string(size) + " bytes)");
  if (facts.point_offset < facts.header_size)
    fail("offset to the points " + std::to_string(facts.point_offset) + " is inside the header (" +
         std::to_string(facts.header_size) + " bytes)");
  if (facts.point_offset > size)
    fail("offset to the points " + std::to_string(facts.point_offset) +
         " is past the end of the file (" + std::to_string(size) + " bytes)");
  if (layout.point_format > 10)
    fail("unknown point data record format " + std::to_string(layout.point_format) +
         " (0 to 10 are defined)");
  const std::uint16_t format_size = lasPointFormatSize(layout.point_format);
  if (layout.record_length < format_size)
    fail("point record length " + std::to_string(layout.record_length) +
         " is smaller than point format " + std::to_string(layout.point_format) + "'s " +
         std::to_string(format_size) + " bytes");
  requireScale(layout.scale, layout.offset);
  if (layout.version_minor >= 3) facts.waveform_start = get<std::uint64_t>(h + 227);
  facts.points = legacy_points;
  if (layout.version_minor >= 4) {
    facts.evlr_start = get<std::uint64_t>(h + 235);
    facts.evlr_count = get<std::uint32_t>(h + 243);
    facts.points = get<std::uint64_t>(h + 247);
    if (legacy_points != 0 && legacy_points != facts.points)
      fail("the legacy point count " + std::to_string(legacy_points) +
           " differs from the 64-bit point count " + std::to_string(facts.points));
  }
  layout.point_count = facts.points;
  layout.header_extra.assign(h + standard, facts.header_size - standard);

  readRecords(data, facts.header_size, facts.point_offset, facts.vlr_count, false, layout.vlrs);
  std::uint64_t vlr_end = facts.header_size;
  for (const auto& r : layout.vlrs) vlr_end += kVlrHeader + r.data.size();
  layout.after_vlrs.assign(h + vlr_end, facts.point_offset - vlr_end);

  // The points: offset + count x length within the file (and before the EVLRs).
  std::uint64_t point_bytes = 0;
  if (__builtin_mul_overflow(facts.points, std::uint64_t{layout.record_length}, &point_bytes) ||
      point_bytes > size - facts.point_offset)
    fail("the header claims " + std::to_string(facts.points) + " points of " +
         std::to_string(layout.record_length) + " bytes from byte " +
         std::to_string(facts.point_offset) + ", but the file holds " +
         std::to_string((size - facts.point_offset) / layout.record_length) +
         " whole records (truncated, or a lying count)");
  const std::uint64_t points_end = facts.point_offset + point_bytes;
  if (facts.evlr_count > 0) {
    if (facts.evlr_start < points_end || facts.evlr_start > size)
      fail("the EVLRs' start " + std::to_string(facts.evlr_start) +
           " is not between the end of the points (" + std::to_string(points_end) +
           ") and the end of the file (" + std::to_string(size) + ")");
    readRecords(data, facts.evlr_start, size, facts.evlr_count, true, layout.evlrs);
  }
  // The waveform data packets: an EVLR (1.4), or the one record at that offset (1.3).
  const bool internal_waves = (layout.global_encoding & 0x2) != 0;
  if (facts.waveform_start != 0 && internal_waves) {
    if (layout.version_minor >= 4) {
      std::uint64_t at = facts.evlr_start;
      for (std::size_t i = 0; i < layout.evlrs.size(); ++i) {
        if (at == facts.waveform_start) layout.waveform_evlr = static_cast<int>(i);
        at += kEvlrHeader + layout.evlrs[i].data.size();
      }
    } else {
      if (facts.waveform_start < points_end || facts.waveform_start > size)
        fail("the waveform data's start " + std::to_string(facts.waveform_start) +
             " is not after the points");
      readRecords(data, facts.waveform_start, size, 1, true, layout.evlrs);
      layout.waveform_evlr = 0;
    }
  }

  // The Extra Bytes dimensions (a VLR, or in 1.4 possibly an EVLR).
  const LasVariableLengthRecord* extra = nullptr;
  for (const auto* list : {&layout.vlrs, &layout.evlrs}) {
    for (const auto& r : *list) {
      if (extra == nullptr && isExtraBytesRecord(r)) extra = &r;
    }
  }
  std::uint32_t described = 0;
  const std::uint32_t available = layout.record_length - format_size;
  if (extra != nullptr) {
    if (extra->data.size() % kDescriptorSize != 0)
      fail("the Extra Bytes VLR's length " + std::to_string(extra->data.size()) +
           " is not a multiple of 192");
    for (std::size_t k = 0; k < extra->data.size() / kDescriptorSize; ++k) {
      LasExtraBytesDimension dim;
      dim.descriptor = extra->data.substr(k * kDescriptorSize, kDescriptorSize);
      described += byteSize(extraType(dim.descriptor.data(), k));
      if (described > available)
        fail("the Extra Bytes VLR describes " + std::to_string(described) +
             " bytes or more, but the records have " + std::to_string(available) +
             " bytes beyond point format " + std::to_string(layout.point_format) + "'s");
      layout.extra_bytes.push_back(std::move(dim));
    }
  }
  layout.undocumented_bytes = available - described;
  return layout;
}

struct Copy {
  std::uint32_t from, to, size;
};
struct Scaled {  // an Extra Bytes dimension with a scale or offset: raw -> double
  std::uint32_t from, to;
  std::uint8_t raw_type;
  std::uint32_t count;
  ExtraScaling scaling;
};
struct Bits {
  std::uint32_t from, to;
  std::uint8_t shift, mask;
};

pcl::PCLPointField makeField(const std::string& name, std::uint8_t datatype, std::uint32_t offset,
                             std::uint32_t count = 1) {
  pcl::PCLPointField f;
  f.name = name;
  f.datatype = datatype;
  f.offset = offset;
  f.count = count;
  return f;
}

}  // namespace

LasCloud parseLAS(std::string_view data) {
  HeaderFacts facts;
  LasCloud result;
  LasLayout& layout = result.layout;
  layout = parseLayout(data, facts);

  // The cloud's fields: float x y z (PCL's), the format's, the extra bytes, undocumented bytes.
  pcl::PCLPointCloud2& cloud = result.mesh.cloud;
  std::uint32_t step = 0;
  for (const char* axis : {"x", "y", "z"}) {
    cloud.fields.push_back(makeField(axis, F::FLOAT32, step));
    step += 4;
  }
  std::vector<Copy> copies;
  std::vector<Bits> bits;
  std::vector<Scaled> scaled;
  for (const CoreField& core : coreFields(layout.point_format)) {
    cloud.fields.push_back(makeField(core.name, core.datatype, step));
    const std::uint32_t size = pcl::getFieldSize(core.datatype);
    if (core.bits > 0) {
      bits.push_back(
          {core.offset, step, core.shift, static_cast<std::uint8_t>((1u << core.bits) - 1u)});
    } else {
      copies.push_back({core.offset, step, size});
    }
    step += size;
  }
  const auto taken = [&](const std::string& name) {
    return std::any_of(cloud.fields.begin(), cloud.fields.end(),
                       [&](const pcl::PCLPointField& f) { return f.name == name; });
  };
  std::uint32_t at = lasPointFormatSize(layout.point_format);
  for (std::size_t k = 0; k < layout.extra_bytes.size(); ++k) {
    LasExtraBytesDimension& dim = layout.extra_bytes[k];
    const ExtraType type = extraType(dim.descriptor.data(), k);
    const std::string base = cloudNameOf(upToNul(dim.descriptor.substr(4, 32)), k);
    std::string name = base;
    for (int n = 2; taken(name) || name == kLasUndocumentedBytesField; ++n)
      name = base + "_" + std::to_string(n);
    dim.field = name;
    const ExtraScaling scaling = extraScaling(dim.descriptor);
    if (scaling.scaled) {
      cloud.fields.push_back(makeField(name, F::FLOAT64, step, type.count));
      scaled.push_back({at, step, type.datatype, type.count, scaling});
      step += 8 * type.count;
    } else {
      cloud.fields.push_back(makeField(name, type.datatype, step, type.count));
      copies.push_back({at, step, byteSize(type)});
      step += byteSize(type);
    }
    at += byteSize(type);
  }
  if (layout.undocumented_bytes > 0) {
    cloud.fields.push_back(
        makeField(kLasUndocumentedBytesField, F::UINT8, step, layout.undocumented_bytes));
    copies.push_back({at, step, layout.undocumented_bytes});
    step += layout.undocumented_bytes;
  }
  // Merge adjacent copies (the extra bytes are contiguous in both layouts).
  std::vector<Copy> merged;
  for (const Copy& c : copies) {
    if (!merged.empty() && merged.back().from + merged.back().size == c.from &&
        merged.back().to + merged.back().size == c.to) {
      merged.back().size += c.size;
    } else {
      merged.push_back(c);
    }
  }

  const std::uint64_t n = facts.points;
  if (n > std::numeric_limits<std::uint32_t>::max() ||
      n * step > std::numeric_limits<std::uint32_t>::max())
    fail(std::to_string(n) + " points of " + std::to_string(step) +
         " bytes are too many for a pcl::PCLPointCloud2 (4 GiB)");
  cloud.width = static_cast<std::uint32_t>(n);
  cloud.height = 1;
  cloud.point_step = step;
  cloud.row_step = static_cast<std::uint32_t>(n * step);
  cloud.is_dense = true;  // integers times a finite scale plus a finite offset
  cloud.data.resize(static_cast<std::size_t>(n * step));
  result.positions.resize(3, static_cast<Eigen::Index>(n));

  const char* records = data.data() + facts.point_offset;
  const std::size_t length = layout.record_length;
  const Eigen::Vector3d scale = layout.scale, offset = layout.offset;
  std::uint8_t* out = cloud.data.data();
  double* positions = result.positions.data();
  const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) if (count > 100000)
  for (std::int64_t i = 0; i < count; ++i) {
    const char* record = records + static_cast<std::size_t>(i) * length;
    std::uint8_t* point = out + static_cast<std::size_t>(i) * step;
    for (int d = 0; d < 3; ++d) {
      const double v = get<std::int32_t>(record + 4 * d) * scale[d] + offset[d];
      positions[3 * i + d] = v;
      put(reinterpret_cast<char*>(point) + 4 * d, static_cast<float>(v));
    }
    for (const Copy& c : merged) std::memcpy(point + c.to, record + c.from, c.size);
    for (const Bits& b : bits)
      point[b.to] = static_cast<std::uint8_t>(
          (static_cast<std::uint8_t>(record[b.from]) >> b.shift) & b.mask);
    for (const Scaled& e : scaled) {
      const std::uint32_t size = pcl::getFieldSize(e.raw_type);
      for (std::uint32_t j = 0; j < e.count; ++j) {
        const double raw = rawValue(record + e.from + j * size, e.raw_type);
        put(reinterpret_cast<char*>(point) + e.to + 8 * j,
            raw * e.scaling.scale[j] + e.scaling.offset[j]);
      }
    }
  }
  // A coordinate beyond float's range cannot be held by PCL's point types.
  for (std::int64_t i = 0; i < count; ++i) {
    for (int d = 0; d < 3; ++d) {
      if (std::abs(positions[3 * i + d]) > std::numeric_limits<float>::max()) {
        std::ostringstream text;
        text << "point " << i << ": coordinate " << positions[3 * i + d]
             << " is beyond float's range (PCL's point types are float)";
        fail(text.str());
      }
    }
  }
  return result;
}

// --- writing --------------------------------------------------------------------------------

namespace {

const pcl::PCLPointField* findField(const pcl::PCLPointCloud2& cloud, const std::string& name) {
  for (const auto& f : cloud.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

// A scale (a power of ten) and an offset that hold [lo, hi] in 32-bit integers finely.
void chooseScaleAndOffset(double lo, double hi, double& scale, double& offset) {
  if (!(hi >= lo)) {  // no finite point
    scale = 0.001;
    offset = 0.0;
    return;
  }
  const double extent = std::max(hi - lo, std::abs(lo) * 1e-12);
  int k = extent > 0.0 ? static_cast<int>(std::ceil(std::log10(extent / 1e9))) : -3;
  k = std::max(-12, std::min(k, 30));
  for (;; ++k) {  // coarser where doubles could not resolve the steps (far from the origin)
    scale = std::pow(10.0, k);
    const double unit = scale * 1000.0;
    offset = std::floor(lo / unit) * unit;
    if (gridResolvable(scale, offset) || k >= 300) break;
  }
}

std::string padded(const std::string& text, std::size_t size) {
  std::string bytes = text.substr(0, size);
  bytes.resize(size, '\0');
  return bytes;
}

std::string newDescriptor(const std::string& las_name, const pcl::PCLPointField& field) {
  std::string d(kDescriptorSize, '\0');
  const int base = lasTypeOfPcl(field.datatype);
  const std::uint32_t count = std::max<std::uint32_t>(field.count, 1);
  int type = 0, options = 0;
  if (base == 0) {
    fail("field '" + field.name + "' has a type LAS extra bytes cannot hold");
  } else if (count == 1) {
    type = base;
  } else if (count <= 3) {
    type = base + 10 * static_cast<int>(count - 1);  // deprecated arrays, as read
  } else if (field.datatype == F::UINT8 && count <= 255) {
    options = static_cast<int>(count);  // undocumented bytes
  } else {
    fail("field '" + field.name + "' has " + std::to_string(count) +
         " values per point: LAS extra bytes hold 1 to 3");
  }
  d[2] = static_cast<char>(type);
  d[3] = static_cast<char>(options);
  std::memcpy(&d[4], las_name.data(), las_name.size());
  std::memcpy(&d[160], las_name.data(), std::min<std::size_t>(las_name.size(), 32));
  return d;
}

bool descriptorFits(const std::string& descriptor, const pcl::PCLPointField& field) {
  if (descriptor.size() != kDescriptorSize) return false;
  const int type = static_cast<std::uint8_t>(descriptor[2]);
  if (type > 30 || (type == 0 && descriptor[3] == 0)) return false;
  const ExtraType t = extraType(descriptor.data(), 0);
  const std::uint8_t held = extraScaling(descriptor).scaled ? std::uint8_t{F::FLOAT64} : t.datatype;
  return held == field.datatype && t.count == std::max<std::uint32_t>(field.count, 1);
}

// Where a value of the cloud goes in the record.
struct Slot {
  const pcl::PCLPointField* field;
  std::uint32_t to;
  std::uint32_t size;
};
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

std::uint8_t byteValue(const std::uint8_t* point, const pcl::PCLPointField& f) {
  return point[f.offset];
}

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

/** size bytes in fixed-size moves: a memcpy of a size unknown at compile time is a call, and a
 *  record takes several such copies. */
inline void copyBytes(char* to, const std::uint8_t* from, std::uint32_t size) {
  for (; size >= 8; size -= 8, to += 8, from += 8) std::memcpy(to, from, 8);
  if (size >= 4) {
    std::memcpy(to, from, 4);
    to += 4;
    from += 4;
    size -= 4;
  }
  if (size >= 2) {
    std::memcpy(to, from, 2);
    to += 2;
    from += 2;
    size -= 2;
  }
  if (size != 0) *to = static_cast<char>(*from);
}

/** The plan for writing cloud: source's layout, or LAS 1.4 format 6/7 whose scale and offset are
 *  chosen from finite_bounds() (called only then). */
LasPlan planLAS(const pcl::PCLPointCloud2& cloud, const LasLayout* source,
                const std::function<Eigen::AlignedBox3d()>& finite_bounds) {
  LasPlan plan;
  LasLayout& layout = plan.layout;
  if (source != nullptr) {
    layout = *source;
  } else {
    layout.version_major = 1;
    layout.version_minor = 4;
    layout.point_format = vertexColorLayout(cloud) ? 7 : 6;
    layout.system_identifier = padded("pcl_ddg", 32);
  }
  if (layout.version_major != 1 || layout.version_minor > 4 || layout.point_format > 10)
    fail("cannot write LAS " + std::to_string(layout.version_major) + "." +
         std::to_string(layout.version_minor) + " point format " +
         std::to_string(layout.point_format));
  layout.generating_software = padded("pcl_ddg", 32);
  if (source == nullptr) {
    const Eigen::AlignedBox3d box = finite_bounds();
    for (int d = 0; d < 3; ++d) {
      chooseScaleAndOffset(box.isEmpty() ? 1.0 : box.min()[d], box.isEmpty() ? 0.0 : box.max()[d],
                           layout.scale[d], layout.offset[d]);
    }
  }
  requireScale(layout.scale, layout.offset);
  const int format = layout.point_format;
  const bool extended = format >= 6;

  // The format's fields, from the cloud's fields of the same name and type.
  std::vector<std::string> consumed = {"x", "y", "z", "_", kLasUndocumentedBytesField};
  std::vector<Slot> slots;
  std::vector<BitSlot> bit_slots;
  bool has_rgb = false;
  const pcl::PCLPointField* rank = nullptr;  // scan_angle_rank for a 6-10 record, or the reverse
  std::uint32_t angle_to = 0;
  for (const CoreField& core : coreFields(format)) {
    const pcl::PCLPointField* f = findField(cloud, core.name);
    const bool usable = f != nullptr && f->datatype == core.datatype && f->count == 1;
    if (std::string(core.name) == "red") has_rgb = true;
    if (core.bits > 0) {
      const bool returns = std::string(core.name) == "return_number" ||
                           std::string(core.name) == "number_of_returns";
      bit_slots.push_back({usable ? f : nullptr, core.offset, core.shift, core.bits,
                           static_cast<std::uint8_t>(returns ? 1 : 0),
                           std::string(core.name) == "return_number"});
    } else if (usable) {
      slots.push_back(
          {f, core.offset, static_cast<std::uint32_t>(pcl::getFieldSize(core.datatype))});
    } else if (std::string(core.name) == "scan_angle" ||
               std::string(core.name) == "scan_angle_rank") {
      const char* other = extended ? "scan_angle_rank" : "scan_angle";
      const pcl::PCLPointField* g = findField(cloud, other);
      if (g != nullptr && g->count == 1 && g->datatype == (extended ? F::INT8 : F::INT16)) {
        rank = g;
        angle_to = core.offset;
        consumed.push_back(other);
      }
    }
    if (usable) consumed.push_back(core.name);
  }
  // Colours of another layout (8-bit channels, packed rgb) into a format with RGB: 16 bits.
  const bool rgb16 = has_rgb && std::count(consumed.begin(), consumed.end(), "red") > 0 &&
                     std::count(consumed.begin(), consumed.end(), "green") > 0 &&
                     std::count(consumed.begin(), consumed.end(), "blue") > 0;
  bool convert_colors = false;
  std::uint32_t rgb_to = 0;
  if (has_rgb && !rgb16 && vertexColorLayout(cloud)) {
    convert_colors = true;
    for (const CoreField& core : coreFields(format)) {
      if (std::string(core.name) == "red") rgb_to = core.offset;
    }
    slots.erase(std::remove_if(slots.begin(), slots.end(),
                               [&](const Slot& s) { return s.to >= rgb_to && s.to < rgb_to + 6; }),
                slots.end());
    for (const char* name : {"red", "green", "blue", "alpha", "rgb", "rgba"})
      consumed.push_back(name);
  }

  // Every other field: an Extra Bytes dimension, its descriptor kept when it still fits.
  std::vector<LasExtraBytesDimension> dims;
  std::vector<Slot> extra_slots;
  std::uint32_t extra_size = 0;
  const std::uint16_t format_size = lasPointFormatSize(format);
  for (const auto& f : cloud.fields) {
    if (std::find(consumed.begin(), consumed.end(), f.name) != consumed.end()) continue;
    if (pcl::getFieldSize(f.datatype) == 0) continue;
    LasExtraBytesDimension dim;
    dim.field = f.name;
    if (source != nullptr) {
      for (const auto& kept : source->extra_bytes) {
        if (kept.field == f.name && descriptorFits(kept.descriptor, f))
          dim.descriptor = kept.descriptor;
      }
    }
    if (dim.descriptor.empty()) {
      const std::string las_name = lasNameOf(f.name);
      if (las_name.size() > 32)
        fail("field name '" + f.name + "' is longer than the 32 bytes of an Extra Bytes name");
      dim.descriptor = newDescriptor(las_name, f);
    }
    std::uint32_t size = pcl::getFieldSize(f.datatype) * std::max<std::uint32_t>(f.count, 1);
    const ExtraScaling scaling = extraScaling(dim.descriptor);
    if (scaling.scaled) {  // doubles back into the raw type (a kept descriptor's)
      const ExtraType raw = extraType(dim.descriptor.data(), 0);
      size = byteSize(raw);
      plan.scaled.push_back({&f, format_size + extra_size, raw.datatype, raw.count, scaling});
    } else {
      extra_slots.push_back({&f, format_size + extra_size, size});
    }
    extra_size += size;
    dims.push_back(std::move(dim));
  }
  const pcl::PCLPointField* undocumented = findField(cloud, kLasUndocumentedBytesField);
  if (undocumented != nullptr && undocumented->datatype != F::UINT8) undocumented = nullptr;
  const std::uint32_t undocumented_size = undocumented ? undocumented->count : 0;
  const std::uint64_t record_length = std::uint64_t{format_size} + extra_size + undocumented_size;
  if (record_length > std::numeric_limits<std::uint16_t>::max())
    fail("a point record of " + std::to_string(record_length) + " bytes exceeds LAS's 65,535");

  // The Extra Bytes VLR: rewritten in place, added, or dropped.
  std::string descriptors;
  for (const auto& dim : dims) descriptors += dim.descriptor;
  bool placed = false;
  for (auto* list : {&layout.vlrs, &layout.evlrs}) {
    for (auto it = list->begin(); it != list->end();) {
      if (!isExtraBytesRecord(*it) || placed) {  // every other record as it was
        ++it;
        continue;
      }
      if (descriptors.empty() && !it->data.empty()) {  // (an empty one is kept as it was)
        it = list->erase(it);
        continue;
      }
      it->data = descriptors;
      placed = true;
      ++it;
    }
  }
  if (!placed && !descriptors.empty()) {
    LasVariableLengthRecord r;
    r.user_id = padded("LASF_Spec", 16);
    r.record_id = 4;
    r.description = padded("Extra Bytes Record", 32);
    r.data = descriptors;
    layout.vlrs.push_back(std::move(r));
  }
  for (const auto& r : layout.vlrs) {
    if (r.data.size() > std::numeric_limits<std::uint16_t>::max())
      fail("VLR '" + r.userId() + "' " + std::to_string(r.record_id) + " holds " +
           std::to_string(r.data.size()) + " bytes, more than a VLR's 65,535");
  }
  if (layout.version_minor < 4 && layout.evlrs.size() > (layout.waveform_evlr >= 0 ? 1u : 0u))
    fail("EVLRs other than the waveform data need LAS 1.4");

  // Sizes and offsets.
  const std::size_t standard = headerSizeOf(layout.version_minor);
  const std::uint64_t header_size = standard + layout.header_extra.size();
  std::uint64_t point_offset = header_size + layout.after_vlrs.size();
  for (const auto& r : layout.vlrs) point_offset += kVlrHeader + r.data.size();
  if (header_size > std::numeric_limits<std::uint16_t>::max() ||
      point_offset > std::numeric_limits<std::uint32_t>::max())
    fail("the header and VLRs are too large");
  plan.format = format;
  plan.extended = extended;
  // Every byte copied as it is (the format's fields, Extra Bytes, undocumented bytes), in runs:
  // a cloud read from LAS holds them in the record's order, so a record takes a few copies.
  for (const auto* list : {&slots, &extra_slots}) {
    for (const Slot& slot : *list) plan.copies.push_back({slot.field->offset, slot.to, slot.size});
  }
  if (undocumented != nullptr) {
    plan.copies.push_back({undocumented->offset,
                           static_cast<std::uint32_t>(format_size + extra_size),
                           undocumented_size});
  }
  std::sort(plan.copies.begin(), plan.copies.end(),
            [](const ByteCopy& a, const ByteCopy& b) { return a.to < b.to; });
  std::vector<ByteCopy> runs;
  for (const ByteCopy& c : plan.copies) {
    if (!runs.empty() && runs.back().from + runs.back().size == c.from &&
        runs.back().to + runs.back().size == c.to) {
      runs.back().size += c.size;
    } else {
      runs.push_back(c);
    }
  }
  plan.copies = std::move(runs);
  plan.bit_slots = std::move(bit_slots);
  plan.rank = rank;
  plan.angle_to = angle_to;
  plan.convert_colors = convert_colors;
  plan.rgb_to = rgb_to;
  plan.record_length = record_length;
  plan.standard = standard;
  plan.header_size = header_size;
  plan.point_offset = point_offset;
  return plan;
}

/** Encodes point i (record at `record`, zeroed) from the cloud's row and its exact position;
 *  false, and why in `error`, for a point LAS cannot hold. */
bool encodeRecord(const LasPlan& plan, const pcl::PCLPointCloud2& cloud, std::size_t i,
                  const double* position, const std::uint8_t* color, char* record,
                  RecordStats& stats, std::string& error) {
  const LasLayout& layout = plan.layout;
  const std::uint8_t* point = cloud.data.data() + i * cloud.point_step;
  for (int d = 0; d < 3; ++d) {
    const double v = position[d];
    const double x = (v - layout.offset[d]) / layout.scale[d];
    // std::round inline where |x| fits 32 bits (x - trunc(x) is exact), std::round elsewhere.
    double q;
    if (std::abs(x) < 2147483648.0) {
      const double t = static_cast<double>(static_cast<std::int64_t>(x));
      q = x - t >= 0.5 ? t + 1.0 : x - t <= -0.5 ? t - 1.0 : t;
    } else {
      q = std::round(x);
    }
    if (!std::isfinite(v) || !(q >= -2147483648.0 && q <= 2147483647.0)) {
      std::ostringstream text;
      text.precision(17);
      text << "point " << i << ": " << static_cast<char>('x' + d) << " = " << v
           << (std::isfinite(v) ? " does not fit a 32-bit integer with scale " +
                                      std::to_string(layout.scale[d]) + " and offset " +
                                      std::to_string(layout.offset[d])
                                : " is not finite (LAS stores integers)");
      error = text.str();
      return false;
    }
    const auto X = static_cast<std::int32_t>(q);
    put(record + 4 * d, X);
    stats.lo[d] = std::min<std::int64_t>(stats.lo[d], X);
    stats.hi[d] = std::max<std::int64_t>(stats.hi[d], X);
  }
  stats.any = true;
  for (const ByteCopy& c : plan.copies) copyBytes(record + c.to, point + c.from, c.size);
  int return_number = 0;
  for (const BitSlot& b : plan.bit_slots) {
    const std::uint8_t v = b.field ? byteValue(point, *b.field) : b.fallback;
    if ((v >> b.bits) != 0 && b.field != nullptr) {
      error = "point " + std::to_string(i) + ": " + b.field->name + " " + std::to_string(v) +
              " does not fit point format " + std::to_string(plan.format) + "'s " +
              std::to_string(b.bits) + " bits" +
              (b.field->name == "classification" ? " (classes above 31 need formats 6-10)" : "");
      return false;
    }
    record[b.to] = static_cast<char>(static_cast<std::uint8_t>(record[b.to]) | (v << b.shift));
    if (b.is_return_number) return_number = v;
  }
  if (return_number >= 1 && return_number <= 15) ++stats.by_return[return_number - 1];
  if (plan.rank != nullptr) {
    const char* from = reinterpret_cast<const char*>(point) + plan.rank->offset;
    if (plan.extended) {  // degrees -> 0.006 degree steps
      put(record + plan.angle_to,
          static_cast<std::int16_t>(std::lround(get<std::int8_t>(from) / 0.006)));
    } else {
      put(record + plan.angle_to,
          static_cast<std::int8_t>(std::lround(get<std::int16_t>(from) * 0.006)));
    }
  }
  for (const ScaledSlot& e : plan.scaled) {
    const std::uint32_t size = pcl::getFieldSize(e.raw_type);
    for (std::uint32_t j = 0; j < e.count; ++j) {
      const double v = get<double>(reinterpret_cast<const char*>(point) + e.field->offset + 8 * j);
      if (!putRawValue(record + e.to + j * size, e.raw_type,
                       (v - e.scaling.offset[j]) / e.scaling.scale[j])) {
        std::ostringstream text;
        text.precision(17);
        text << "point " << i << ": " << e.field->name << " = " << v
             << " does not fit its Extra Bytes type with scale " << e.scaling.scale[j]
             << " and offset " << e.scaling.offset[j];
        error = text.str();
        return false;
      }
    }
  }
  if (color != nullptr) {
    for (int c = 0; c < 3; ++c)
      put(record + plan.rgb_to + 2 * c, static_cast<std::uint16_t>(color[c] * 257));
  }
  return true;
}

/** Records [first, first + positions.cols()) into `records` (zeroed); throws for the first point
 *  LAS cannot hold. */
void encodeRecords(const LasPlan& plan, const pcl::PCLPointCloud2& cloud, std::size_t first,
                   const Eigen::Matrix3Xd& positions, const VertexColors& colors, char* records,
                   RecordStats& stats) {
  std::string error;
  for (Eigen::Index j = 0; j < positions.cols(); ++j) {
    if (!encodeRecord(plan, cloud, first + static_cast<std::size_t>(j), positions.col(j).data(),
                      colors.cols() > 0 ? colors.data() + 3 * j : nullptr,
                      records + j * plan.record_length, stats, error))
      fail(error);
  }
}

/** Where the file's parts go: bytes at an offset. */
using ByteSink = std::function<void(std::uint64_t at, const char* bytes, std::size_t size)>;

/** Writes the header, VLRs and EVLRs of a file of n records with these stats (the records
 *  themselves are written by the caller). */
void writeHeaderAndRecords(const LasPlan& plan, std::size_t n, const RecordStats& stats,
                           const ByteSink& sink) {
  const LasLayout& layout = plan.layout;
  const int format = plan.format;
  const std::uint64_t points_end = plan.point_offset + plan.record_length * n;
  // Bounds from the integers (x = X * scale + offset is monotonic in X).
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  for (int d = 0; d < 3 && stats.any; ++d) {
    const double a = static_cast<double>(static_cast<std::int32_t>(stats.lo[d])) * layout.scale[d] +
                     layout.offset[d],
                 b = static_cast<double>(static_cast<std::int32_t>(stats.hi[d])) * layout.scale[d] +
                     layout.offset[d];
    lo[d] = std::min(a, b);
    hi[d] = std::max(a, b);
  }
  const auto& by_return = stats.by_return;
  std::string header(static_cast<std::size_t>(plan.point_offset), '\0');
  char* h = header.data();
  std::memcpy(h, "LASF", 4);
  put(h + 4, layout.file_source_id);
  put(h + 6, layout.global_encoding);
  std::memcpy(h + 8, padded(layout.project_id, 16).data(), 16);
  h[24] = static_cast<char>(layout.version_major);
  h[25] = static_cast<char>(layout.version_minor);
  std::memcpy(h + 26, padded(layout.system_identifier, 32).data(), 32);
  std::memcpy(h + 58, padded(layout.generating_software, 32).data(), 32);
  put(h + 90, layout.creation_day);
  put(h + 92, layout.creation_year);
  put(h + 94, static_cast<std::uint16_t>(plan.header_size));
  put(h + 96, static_cast<std::uint32_t>(plan.point_offset));
  put(h + 100, static_cast<std::uint32_t>(layout.vlrs.size()));
  h[104] = static_cast<char>(format);
  put(h + 105, static_cast<std::uint16_t>(plan.record_length));
  // Legacy counts: always below 1.4; in 1.4 for formats 0-5 when they fit, zero for 6-10.
  if (layout.version_minor < 4 && n > 0xffffffffu)
    fail(std::to_string(n) + " points need LAS 1.4 (64-bit counts)");
  if (layout.version_minor < 4 || (!plan.extended && n <= 0xffffffffu)) {
    put(h + 107, static_cast<std::uint32_t>(n));
    for (int r = 0; r < 5; ++r) put(h + 111 + 4 * r, static_cast<std::uint32_t>(by_return[r]));
  }
  for (int d = 0; d < 3; ++d) {
    put(h + 131 + 8 * d, layout.scale[d]);
    put(h + 155 + 8 * d, layout.offset[d]);
    put(h + 179 + 16 * d, hi[d]);
    put(h + 187 + 16 * d, lo[d]);
  }
  std::uint64_t at = points_end;
  std::uint64_t waveform_start = 0;
  for (std::size_t k = 0; k < layout.evlrs.size(); ++k) {
    const auto& r = layout.evlrs[k];
    if (static_cast<int>(k) == layout.waveform_evlr) waveform_start = at;
    std::string e(kEvlrHeader + r.data.size(), '\0');
    char* p = e.data();
    put(p, r.reserved);
    std::memcpy(p + 2, padded(r.user_id, 16).data(), 16);
    put(p + 18, r.record_id);
    put(p + 20, static_cast<std::uint64_t>(r.data.size()));
    std::memcpy(p + 28, padded(r.description, 32).data(), 32);
    std::memcpy(p + kEvlrHeader, r.data.data(), r.data.size());
    sink(at, e.data(), e.size());
    at += e.size();
  }
  if (layout.version_minor >= 3) put(h + 227, waveform_start);
  if (layout.version_minor >= 4) {
    put(h + 235, layout.evlrs.empty() ? std::uint64_t{0} : points_end);
    put(h + 243, static_cast<std::uint32_t>(layout.evlrs.size()));
    put(h + 247, static_cast<std::uint64_t>(n));
    for (int r = 0; r < 15; ++r) put(h + 255 + 8 * r, by_return[r]);
  }
  std::memcpy(h + plan.standard, layout.header_extra.data(), layout.header_extra.size());
  std::uint64_t p = plan.header_size;
  for (const auto& r : layout.vlrs) {
    char* v = header.data() + p;
    put(v, r.reserved);
    std::memcpy(v + 2, padded(r.user_id, 16).data(), 16);
    put(v + 18, r.record_id);
    put(v + 20, static_cast<std::uint16_t>(r.data.size()));
    std::memcpy(v + 22, padded(r.description, 32).data(), 32);
    std::memcpy(v + kVlrHeader, r.data.data(), r.data.size());
    p += kVlrHeader + r.data.size();
  }
  std::memcpy(header.data() + p, layout.after_vlrs.data(), layout.after_vlrs.size());
  sink(0, header.data(), header.size());
}

// Points encoded at once by writeLAS: a few MB of records, reused.
constexpr std::size_t kBlockPoints = 1 << 18;

Eigen::AlignedBox3d finiteBounds(const Eigen::Matrix3Xd& positions) {
  Eigen::AlignedBox3d box;
  for (Eigen::Index i = 0; i < positions.cols(); ++i)
    if (positions.col(i).allFinite()) box.extend(Eigen::Vector3d(positions.col(i)));
  return box;
}

/** The rows [first, first + count) of cloud as a cloud of their own. */
pcl::PCLPointCloud2 rowsOf(const pcl::PCLPointCloud2& cloud, std::size_t first, std::size_t count) {
  pcl::PCLPointCloud2 block;
  block.fields = cloud.fields;
  block.point_step = cloud.point_step;
  block.is_bigendian = cloud.is_bigendian;
  block.width = static_cast<std::uint32_t>(count);
  block.height = 1;
  block.row_step = block.point_step * block.width;
  const auto* from = cloud.data.data() + first * cloud.point_step;
  block.data.assign(from, from + count * cloud.point_step);
  return block;
}

/** The exact coordinates of rows [first, first + count): read in place from float or double
 *  fields, through a copy of the rows for any other type. */
Eigen::Matrix3Xd blockPositions(const pcl::PCLPointCloud2& cloud, std::size_t first,
                                std::size_t count) {
  const pcl::PCLPointField* xyz[3] = {findField(cloud, "x"), findField(cloud, "y"),
                                      findField(cloud, "z")};
  const auto same = [&](std::uint8_t type) {
    return std::all_of(xyz, xyz + 3,
                       [&](const pcl::PCLPointField* f) { return f && f->datatype == type; });
  };
  if (!same(F::FLOAT64) && !same(F::FLOAT32))
    return vertexPositions(rowsOf(cloud, first, count), NonFinitePolicy::Keep);
  Eigen::Matrix3Xd positions(3, static_cast<Eigen::Index>(count));
  const bool doubles = same(F::FLOAT64);
  for (std::size_t i = 0; i < count; ++i) {
    const char* row =
        reinterpret_cast<const char*>(cloud.data.data()) + (first + i) * cloud.point_step;
    for (int d = 0; d < 3; ++d) {
      positions(d, static_cast<Eigen::Index>(i)) =
          doubles ? get<double>(row + xyz[d]->offset) : get<float>(row + xyz[d]->offset);
    }
  }
  return positions;
}

}  // namespace

std::string encodeLAS(const pcl::PCLPointCloud2& cloud, const Eigen::Matrix3Xd& positions,
                      const LasLayout* source) {
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (static_cast<std::size_t>(positions.cols()) != n)
    fail("positions do not match the point count");
  const LasPlan plan = planLAS(cloud, source, [&] { return finiteBounds(positions); });
  std::uint64_t evlr_bytes = 0;
  for (const auto& r : plan.layout.evlrs) evlr_bytes += kEvlrHeader + r.data.size();
  std::string file(
      static_cast<std::size_t>(plan.point_offset + plan.record_length * n + evlr_bytes), '\0');
  const VertexColors colors = plan.convert_colors ? vertexColors(cloud) : VertexColors();
  RecordStats stats;
  encodeRecords(plan, cloud, 0, positions, colors, file.data() + plan.point_offset, stats);
  writeHeaderAndRecords(plan, n, stats, [&](std::uint64_t at, const char* bytes, std::size_t size) {
    std::memcpy(file.data() + at, bytes, size);
  });
  return file;
}

namespace {

void pwriteAll(int fd, const std::string& path, std::uint64_t at, const char* bytes,
               std::size_t size) {
  for (std::size_t done = 0; done < size;) {
    const ssize_t w = ::pwrite(fd, bytes + done, size - done, static_cast<off_t>(at + done));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      throw FileFormatException("cannot write '" + path +
                                "': " + std::strerror(w < 0 ? errno : ENOSPC));
    }
    done += static_cast<std::size_t>(w);
  }
}

}  // namespace

void writeLAS(const std::string& path, const pcl::PCLPointCloud2& cloud, const LasLayout* source) {
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  const LasPlan plan = planLAS(cloud, source, [&] {
    Eigen::AlignedBox3d box;
    for (std::size_t first = 0; first < n; first += kBlockPoints)
      box.extend(finiteBounds(blockPositions(cloud, first, std::min(kBlockPoints, n - first))));
    return box;
  });
  std::uint64_t evlr_bytes = 0;
  for (const auto& r : plan.layout.evlrs) evlr_bytes += kEvlrHeader + r.data.size();
  const std::uint64_t size = plan.point_offset + plan.record_length * n + evlr_bytes;
  const auto failed = [&](int error) {
    return FileFormatException("cannot write '" + path + "': " + std::strerror(error));
  };
  // O_RDWR: a shared mapping needs a descriptor open for reading too.
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw failed(errno);
  struct Closer {
    int fd;
    ~Closer() {
      if (fd >= 0) ::close(fd);
    }
  } closer{fd};
  // The file at its full size with its blocks reserved (a full disk is this error, not a SIGBUS
  // while writing into the mapping), then mapped: the records are encoded straight into the page
  // cache, which the kernel hands out zeroed, with no buffer to clear and no copy to make.
  if (const int error = ::posix_fallocate(fd, 0, static_cast<off_t>(size))) throw failed(error);
  void* const mapping =
      ::mmap(nullptr, static_cast<std::size_t>(size), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (mapping == MAP_FAILED) {
    // A file system without shared writable mappings (some FUSE mounts): encoded in memory, then
    // written.
    const std::string bytes = encodeLAS(cloud, blockPositions(cloud, 0, n), source);
    pwriteAll(fd, path, 0, bytes.data(), bytes.size());
    closer.fd = -1;
    if (::close(fd) != 0) throw failed(errno);
    return;
  }
  struct Unmapper {
    void* at;
    std::size_t size;
    ~Unmapper() { ::munmap(at, size); }
  } unmapper{mapping, static_cast<std::size_t>(size)};
  char* const file = static_cast<char*>(mapping);
  // Blocks on every core: each encodes its records and faults its pages in on its own. The stats
  // are merged in block order, and the first block that fails names the first point that does.
  const auto blocks = static_cast<std::ptrdiff_t>((n + kBlockPoints - 1) / kBlockPoints);
  std::vector<RecordStats> block_stats(static_cast<std::size_t>(blocks));
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(blocks));
#pragma omp parallel for schedule(dynamic, 1)
  for (std::ptrdiff_t block = 0; block < blocks; ++block) {
    const auto b = static_cast<std::size_t>(block);
    const std::size_t first = b * kBlockPoints;
    const std::size_t count = std::min(kBlockPoints, n - first);
    try {
      const VertexColors colors =
          plan.convert_colors ? vertexColors(rowsOf(cloud, first, count)) : VertexColors();
      encodeRecords(plan, cloud, first, blockPositions(cloud, first, count), colors,
                    file + plan.point_offset + first * plan.record_length, block_stats[b]);
    } catch (...) {
      errors[b] = std::current_exception();
    }
  }
  RecordStats stats;
  for (std::size_t b = 0; b < block_stats.size(); ++b) {
    if (errors[b]) std::rethrow_exception(errors[b]);
    stats.add(block_stats[b]);
  }
  writeHeaderAndRecords(plan, n, stats,
                        [&](std::uint64_t at, const char* bytes, std::size_t length) {
                          std::memcpy(file + at, bytes, length);
                        });
  closer.fd = -1;
  if (::close(fd) != 0) throw failed(errno);
}

struct LasPieceWriter::State {
  pcl::PCLPointCloud2 fields;  // the first piece's fields (no points): what the plan points into
  LasPlan plan;
  RecordStats stats;
  std::uint64_t written = 0;
  int fd = -1;
  std::string path;
};

LasPieceWriter::LasPieceWriter(const std::string& path, const LasLayout& source)
    : source_(source), state_(std::make_unique<State>()) {
  state_->path = path;
  state_->fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (state_->fd < 0)
    throw FileFormatException("cannot write '" + path + "': " + std::strerror(errno));
}

LasPieceWriter::~LasPieceWriter() {
  if (state_->fd >= 0) ::close(state_->fd);
}

void LasPieceWriter::write(const pcl::PCLPointCloud2& piece) {
  State& s = *state_;
  if (s.written == 0 && s.fields.fields.empty()) {
    s.fields.fields = piece.fields;
    s.fields.point_step = piece.point_step;
    s.plan = planLAS(s.fields, &source_, [] { return Eigen::AlignedBox3d(); });
  } else if (piece.point_step != s.fields.point_step ||
             piece.fields.size() != s.fields.fields.size() ||
             !std::equal(piece.fields.begin(), piece.fields.end(), s.fields.fields.begin(),
                         [](const pcl::PCLPointField& a, const pcl::PCLPointField& b) {
                           return a.name == b.name && a.offset == b.offset &&
                                  a.datatype == b.datatype && a.count == b.count;
                         })) {
    fail("a piece's fields differ from the first piece's");
  }
  const std::size_t n = static_cast<std::size_t>(piece.width) * piece.height;
  std::vector<char> records;
  for (std::size_t first = 0; first < n; first += kBlockPoints) {
    const std::size_t count = std::min(kBlockPoints, n - first);
    const VertexColors colors =
        s.plan.convert_colors ? vertexColors(rowsOf(piece, first, count)) : VertexColors();
    records.assign(count * s.plan.record_length, '\0');
    encodeRecords(s.plan, piece, first, blockPositions(piece, first, count), colors, records.data(),
                  s.stats);
    pwriteAll(s.fd, s.path, s.plan.point_offset + (s.written + first) * s.plan.record_length,
              records.data(), records.size());
  }
  s.written += n;
}

void LasPieceWriter::close() {
  State& s = *state_;
  if (s.fields.fields.empty()) fail("no piece was written");
  writeHeaderAndRecords(s.plan, s.written, s.stats,
                        [&](std::uint64_t at, const char* bytes, std::size_t size) {
                          pwriteAll(s.fd, s.path, at, bytes, size);
                        });
  const int fd = s.fd;
  s.fd = -1;
  if (::close(fd) != 0)
    throw FileFormatException("cannot write '" + s.path + "': " + std::strerror(errno));
}

}  // namespace detail
}  // namespace pcl_ddg
