// Writing LAS by a plan (las_plan.h): points encoded into records (exact coordinates rounded to
// the grid, the format's bit fields, scaled Extra Bytes, colours), the header, VLRs and EVLRs
// with the records' bounds and counts, and the whole file: encodeLAS in memory, writeLAS into a
// mapping of the file, a block of points at a time on every core.
#include "las_write.h"

#include <fcntl.h>
#include <pcl/common/io.h>
#include <sys/mman.h>

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <sstream>

#include "las_format.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace detail {
namespace {

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

std::uint8_t byteValue(const std::uint8_t* point, const pcl::PCLPointField& f) {
  return point[f.offset];
}

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

}  // namespace

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

namespace {

Eigen::AlignedBox3d finiteBounds(const Eigen::Matrix3Xd& positions) {
  Eigen::AlignedBox3d box;
  for (Eigen::Index i = 0; i < positions.cols(); ++i)
    if (positions.col(i).allFinite()) box.extend(Eigen::Vector3d(positions.col(i)));
  return box;
}

}  // namespace

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

// Takes the whole pages of [at, at + size), written, out of the process: the file's page cache
// keeps what was written (a shared file mapping's pages are dirty there, not lost), but they no
// longer count in the writer's resident memory, which would otherwise grow by the whole output.
// The pages at the ends, which a neighbouring block may share, stay.
void forgetWrittenPages(char* at, std::size_t size) {
  const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(at) + page - 1) / page * page;
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(at) + size) / page * page;
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_DONTNEED);
}

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
      char* const records = file + plan.point_offset + first * plan.record_length;
      encodeRecords(plan, cloud, first, blockPositions(cloud, first, count), colors, records,
                    block_stats[b]);
      forgetWrittenPages(records, count * plan.record_length);
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

}  // namespace detail
}  // namespace pcl_ddg
