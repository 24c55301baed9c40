// Write planning for LAS (planLAS): the layout a cloud is written in (its source's, or LAS 1.4
// format 6/7 with a scale and offset chosen for it), the point format's fields taken from the
// cloud's, every other field an Extra Bytes dimension, the Extra Bytes VLR and the sizes.
#include "las_plan.h"

#include <pcl/common/io.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "pcl_ddg/io/vertex_fields.h"

namespace pcl_ddg {
namespace detail {

const pcl::PCLPointField* findField(const pcl::PCLPointCloud2& cloud, const std::string& name) {
  for (const auto& f : cloud.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

std::string padded(const std::string& text, std::size_t size) {
  std::string bytes = text.substr(0, size);
  bytes.resize(size, '\0');
  return bytes;
}

namespace {

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

// The source's encoding records (isEncodingRecord) left out.
void dropEncodingRecords(LasLayout& layout) {
  layout.vlrs.erase(std::remove_if(layout.vlrs.begin(), layout.vlrs.end(), isEncodingRecord),
                    layout.vlrs.end());
  std::vector<LasVariableLengthRecord> kept;
  int waveform = -1;
  for (std::size_t i = 0; i < layout.evlrs.size(); ++i) {
    if (isEncodingRecord(layout.evlrs[i])) continue;
    if (static_cast<int>(i) == layout.waveform_evlr) waveform = static_cast<int>(kept.size());
    kept.push_back(std::move(layout.evlrs[i]));
  }
  layout.evlrs = std::move(kept);
  layout.waveform_evlr = waveform;
}

}  // namespace

bool isEncodingRecord(const LasVariableLengthRecord& r) {
  return r.userId() == "copc" || (r.userId() == "laszip encoded" && r.record_id == 22204);
}

LasPlan planLAS(const pcl::PCLPointCloud2& cloud, const LasLayout* source,
                const std::function<Eigen::AlignedBox3d()>& finite_bounds) {
  LasPlan plan;
  LasLayout& layout = plan.layout;
  if (source != nullptr) {
    layout = *source;
    dropEncodingRecords(layout);
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

}  // namespace detail
}  // namespace pcl_ddg
