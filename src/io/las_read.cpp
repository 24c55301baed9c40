// Reading a LAS file (parseLAS): the public header block, the VLRs and EVLRs, every size
// checked against the bytes the file holds before anything is allocated; then the point records
// into the cloud's fields and the exact coordinates.
#include <pcl/common/io.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "las_fields.h"
#include "las_format.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/las_layout.h"

namespace pcl_ddg {

bool lasIsCompressed(std::string_view head) {
  return head.size() > 104 && (static_cast<std::uint8_t>(head[104]) & 0xC0) != 0;
}

bool lazCompressible(int point_format) {
  return (point_format >= 0 && point_format <= 3) || (point_format >= 6 && point_format <= 8);
}

namespace detail {
namespace {

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

// The header, VLRs and EVLRs; the points' place is checked against the file's size.
LasLayout parseLayout(std::string_view data, HeaderFacts& facts) {
  const std::uint64_t size = data.size();
  if (size < 4 || data.substr(0, 4) != "LASF") fail("not a LAS file (no LASF signature)");
  // LAZ first: nothing else of a compressed file is worth reading here (readMeshFile decompresses
  // it, laz/laz_codec.h, before it comes here).
  if (lasIsCompressed(data))
    throw FileFormatException("LAZ (compressed LAS) data: its points must be decompressed first");
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

LasCloud parseLAS(std::string_view data, std::size_t spare_point_bytes) {
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
  if (spare_point_bytes > 0)
    cloud.data.reserve(static_cast<std::size_t>(n * (step + spare_point_bytes)));
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

}  // namespace detail
}  // namespace pcl_ddg
