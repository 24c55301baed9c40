// The LAS format's fields, shared by the reader (las_read.cpp) and the writer (las_write.cpp,
// las_plan.cpp): the point data record formats 0-10, the Extra Bytes descriptors' types, scaling
// and names, the header's sizes and the check of its scale and offset.
#include "las_fields.h"

#include <pcl/common/io.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "pcl_ddg/exceptions.h"

namespace pcl_ddg {

std::uint16_t lasPointFormatSize(int point_format) {
  static constexpr std::uint16_t kSizes[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  return point_format >= 0 && point_format <= 10 ? kSizes[point_format] : 0;
}

std::string LasVariableLengthRecord::userId() const {
  return detail::upToNul(user_id);
}

std::string LasVariableLengthRecord::descriptionText() const {
  return detail::upToNul(description);
}

namespace detail {

std::string upToNul(const std::string& bytes) {
  return bytes.substr(0, bytes.find('\0'));
}

[[noreturn]] void fail(const std::string& message) {
  throw FileFormatException("LAS: " + message);
}

std::size_t headerSizeOf(int minor) {
  return minor >= 4 ? 375 : minor == 3 ? 235 : 227;
}

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

namespace {

std::uint8_t pclTypeOfLas(int base) {
  static constexpr std::uint8_t kTypes[] = {F::UINT8, F::INT8,   F::UINT16, F::INT16,   F::UINT32,
                                            F::INT32, F::UINT64, F::INT64,  F::FLOAT32, F::FLOAT64};
  return kTypes[base - 1];
}

}  // namespace

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

namespace {

// PDAL's names for normals and curvature in LAS (extra bytes) and ours in clouds (PCD naming).
const std::pair<const char*, const char*> kRenamed[] = {{"NormalX", "normal_x"},
                                                        {"NormalY", "normal_y"},
                                                        {"NormalZ", "normal_z"},
                                                        {"Curvature", "curvature"}};

}  // namespace

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

// --- the header's scale and offset ---------------------------------------------------------

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

}  // namespace detail
}  // namespace pcl_ddg
