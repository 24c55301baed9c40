// COPC: the octree of a LAZ 1.4 file read from its info VLR and hierarchy pages, and chosen
// nodes' points read by the byte ranges of their chunks (see pcl_ddg/io/copc.h).
#include "pcl_ddg/io/copc.h"

#include <fcntl.h>
#include <pcl/exceptions.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <tuple>
#include <utility>

#include "las_format.h"
#include "laz/laz_codec.h"
#include "loader_threads.h"
#include "pcl_ddg/exceptions.h"

namespace pcl_ddg {
namespace detail {
namespace {

constexpr std::size_t kHeaderSize = 375;  // LAS 1.4's, which COPC requires
constexpr std::size_t kVlrHeaderSize = 54;
constexpr std::size_t kInfoSize = 160;
constexpr std::size_t kEntrySize = 32;
constexpr int kMaxDepth = 32;  // a key's x, y, z are 32-bit

template <typename T>
T load(const std::string& bytes, std::size_t at) {
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  return value;
}

[[noreturn]] void fail(const std::string& message) {
  throw FileFormatException("COPC: " + message);
}

std::string keyName(const CopcKey& key) {
  return std::to_string(key.depth) + "-" + std::to_string(key.x) + "-" + std::to_string(key.y) +
         "-" + std::to_string(key.z);
}

/** The file's header and VLRs (everything before its points), checked to be a LAZ 1.4 file of
 *  format 6-8. */
std::string readPrefix(ByteRanges& file) {
  if (file.size() < kHeaderSize) fail("the file is shorter than a LAS 1.4 header");
  const std::string header = file.read(0, kHeaderSize);
  if (header.compare(0, 4, "LASF") != 0) fail("not a LAS file (no \"LASF\" signature)");
  if (header[24] != 1 || header[25] != 4 || load<std::uint16_t>(header, 94) < kHeaderSize)
    fail("not a LAS 1.4 file (COPC files are)");
  const auto format_byte = static_cast<std::uint8_t>(header[104]);
  const int format = format_byte & 0x3F;
  if ((format_byte & 0xC0) == 0 || format < 6 || format > 8)
    fail("not a LAZ file of point format 6, 7 or 8 (format byte " + std::to_string(format_byte) +
         ")");
  const std::uint64_t point_offset = load<std::uint32_t>(header, 96);
  if (point_offset < kHeaderSize || point_offset > file.size())
    fail("the offset to the points " + std::to_string(point_offset) + " is not within the file");
  return header + file.read(kHeaderSize, point_offset - kHeaderSize);
}

/** The info VLR's payload (user "copc", record 1), or empty when the file has none. */
std::string infoPayload(const std::string& prefix) {
  const std::uint32_t vlr_count = load<std::uint32_t>(prefix, 100);
  const std::size_t header_size = load<std::uint16_t>(prefix, 94);
  std::size_t at = header_size;
  for (std::uint32_t i = 0; i < vlr_count && at + kVlrHeaderSize <= prefix.size(); ++i) {
    const std::size_t length = load<std::uint16_t>(prefix, at + 20);
    if (at + kVlrHeaderSize + length > prefix.size()) break;
    const std::string user(prefix.data() + at + 2, strnlen(prefix.data() + at + 2, 16));
    if (user == "copc" && load<std::uint16_t>(prefix, at + 18) == 1)
      return prefix.substr(at + kVlrHeaderSize, length);
    at += kVlrHeaderSize + length;
  }
  return {};
}

bool isCopc(ByteRanges& file) {
  try {
    return infoPayload(readPrefix(file)).size() == kInfoSize;
  } catch (const FileFormatException&) {
    return false;
  }
}

/** Reads the pages from the root on, each once (a page named twice is a cycle or a lie). */
void readHierarchy(ByteRanges& file, std::uint64_t points_begin, std::uint64_t root_offset,
                   std::uint64_t root_size, CopcInfo& info) {
  std::vector<std::pair<std::uint64_t, std::uint64_t>> pending{{root_offset, root_size}};
  std::set<std::uint64_t> seen;
  std::set<std::tuple<int, int, int, int>> keys;
  std::uint64_t sum = 0, chunk_bytes = 0;
  while (!pending.empty()) {
    const auto [offset, size] = pending.back();
    pending.pop_back();
    if (size % kEntrySize != 0 || offset > file.size() || size > file.size() - offset)
      fail("hierarchy page of " + std::to_string(size) + " bytes at " + std::to_string(offset) +
           " is not whole entries within the file");
    if (!seen.insert(offset).second)
      fail("hierarchy page at " + std::to_string(offset) + " is named twice");
    ++info.hierarchy_pages;
    const std::string page = file.read(offset, size);
    for (std::size_t at = 0; at < page.size(); at += kEntrySize) {
      CopcNode node;
      node.key = {load<std::int32_t>(page, at), load<std::int32_t>(page, at + 4),
                  load<std::int32_t>(page, at + 8), load<std::int32_t>(page, at + 12)};
      node.offset = load<std::uint64_t>(page, at + 16);
      const std::int32_t bytes = load<std::int32_t>(page, at + 24);
      const std::int32_t points = load<std::int32_t>(page, at + 28);
      const CopcKey& k = node.key;
      const std::int64_t cubes = std::int64_t{1} << std::clamp(k.depth, 0, kMaxDepth - 1);
      if (k.depth < 0 || k.depth >= kMaxDepth || k.x < 0 || k.y < 0 || k.z < 0 || k.x >= cubes ||
          k.y >= cubes || k.z >= cubes)
        fail("hierarchy entry " + keyName(k) + " is not a node of the octree");
      if (points == -1) {  // another page
        if (bytes < 0) fail("hierarchy entry " + keyName(k) + " names a page of negative size");
        pending.emplace_back(node.offset, static_cast<std::uint64_t>(bytes));
        continue;
      }
      if (points < -1 || bytes < 0)
        fail("hierarchy entry " + keyName(k) + " has " + std::to_string(points) + " points in " +
             std::to_string(bytes) + " bytes");
      if (points > 0 && (node.offset > file.size() ||
                         static_cast<std::uint64_t>(bytes) > file.size() - node.offset))
        fail("node " + keyName(k) + "'s chunk is not within the file");
      if (!keys.emplace(k.depth, k.x, k.y, k.z).second)
        fail("node " + keyName(k) + " is listed twice");
      node.bytes = static_cast<std::uint32_t>(bytes);
      node.points = static_cast<std::uint32_t>(points);
      sum += node.points;
      // Chunks do not overlap: more than the file's bytes in all is a lie (and reading every
      // node would hold more than the file), found before the pages go on.
      chunk_bytes += node.points > 0 ? node.bytes : 0;
      if (chunk_bytes > file.size()) fail("the nodes' chunks add up to more than the file");
      info.nodes.push_back(node);
    }
  }
  if (sum != info.point_count)
    fail("the hierarchy's nodes hold " + std::to_string(sum) + " points, the header " +
         std::to_string(info.point_count));
  // ... and none shares bytes with another or with the header and VLRs.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> chunks;  // begin, end
  for (const CopcNode& node : info.nodes)
    if (node.points > 0) chunks.emplace_back(node.offset, node.offset + node.bytes);
  std::sort(chunks.begin(), chunks.end());
  std::uint64_t end = points_begin;
  for (const auto& [begin, chunk_end] : chunks) {
    if (begin < end)
      fail("a node's chunk at " + std::to_string(begin) +
           " overlaps another chunk or the header and VLRs");
    end = chunk_end;
  }
}

/** In place: keeps the records of an uncompressed LAS file whose coordinates lie in box. */
void keepRecordsWithin(std::string& las, const Eigen::AlignedBox3d& box) {
  const std::uint64_t point_offset = load<std::uint32_t>(las, 96);
  const std::uint16_t length = load<std::uint16_t>(las, 105);
  const std::uint64_t count = load<std::uint64_t>(las, 247);
  Eigen::Vector3d scale, offset;
  for (int d = 0; d < 3; ++d) {
    scale[d] = load<double>(las, 131 + 8 * d);
    offset[d] = load<double>(las, 155 + 8 * d);
  }
  std::uint64_t kept = 0;
  char* records = &las[point_offset];
  for (std::uint64_t i = 0; i < count; ++i) {
    const char* record = records + i * length;
    Eigen::Vector3d p;
    for (int d = 0; d < 3; ++d) {
      std::int32_t raw;
      std::memcpy(&raw, record + 4 * d, 4);
      p[d] = raw * scale[d] + offset[d];
    }
    if (!box.contains(p)) continue;
    if (kept != i) std::memmove(records + kept * length, record, length);
    ++kept;
  }
  // The EVLRs were left out when the nodes were put together: the points end the file.
  las.resize(point_offset + kept * length);
  std::memcpy(&las[247], &kept, 8);
}

/** A file's byte ranges by pread, counting what is read. */
class FileRanges : public ByteRanges {
 public:
  explicit FileRanges(const std::string& path)
      : fd_(open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK)) {
    struct stat status {};
    if (fd_ < 0) throw FileFormatException(path + ": cannot open: " + std::strerror(errno));
    if (fstat(fd_, &status) != 0 || !S_ISREG(status.st_mode)) {
      close(fd_);
      throw FileFormatException(path + ": not a regular file");
    }
    size_ = static_cast<std::uint64_t>(status.st_size);
  }
  ~FileRanges() override { close(fd_); }
  FileRanges(const FileRanges&) = delete;
  FileRanges& operator=(const FileRanges&) = delete;

  std::uint64_t size() const override { return size_; }
  std::string read(std::uint64_t offset, std::uint64_t count) override {
    std::string bytes(count, '\0');
    std::uint64_t done = 0;
    while (done < count) {
      const ssize_t got = pread(fd_, &bytes[done], count - done, static_cast<off_t>(offset + done));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0)
        fail("cannot read bytes " + std::to_string(offset) + " to " +
             std::to_string(offset + count) + " (the file changed?)");
      done += static_cast<std::uint64_t>(got);
    }
    bytes_read_ += count;
    return bytes;
  }

 private:
  int fd_;
  std::uint64_t size_ = 0;
};

/** A partial read's points and what it cost. */
CopcPoints pointsOf(const std::string& las, const FileRanges& file) {
  CopcPoints points;
  points.file = lasMeshFile(las);
  points.bytes_read = file.bytesRead();
  return points;
}

}  // namespace

CopcInfo readCopcInfo(ByteRanges& file) {
  const std::string prefix = readPrefix(file);
  const std::string payload = infoPayload(prefix);
  if (payload.size() != kInfoSize) fail("no COPC info VLR (user \"copc\", record 1, 160 bytes)");
  CopcInfo info;
  for (int d = 0; d < 3; ++d) info.center[d] = load<double>(payload, 8 * d);
  info.halfsize = load<double>(payload, 24);
  info.spacing = load<double>(payload, 32);
  const auto root_offset = load<std::uint64_t>(payload, 40);
  const auto root_size = load<std::uint64_t>(payload, 48);
  info.gpstime_min = load<double>(payload, 56);
  info.gpstime_max = load<double>(payload, 64);
  if (!info.center.allFinite() || !(info.halfsize > 0.0) || !std::isfinite(info.halfsize))
    fail("the octree's centre and half size are not finite and positive");
  info.point_count = load<std::uint64_t>(prefix, 247);
  for (int d = 0; d < 3; ++d) info.scale[d] = load<double>(prefix, 131 + 8 * d);
  // The chunks start after the chunk table's offset (8 bytes at the start of the point data).
  readHierarchy(file, prefix.size() + 8, root_offset, root_size, info);
  return info;
}

std::string copcNodesAsLas(ByteRanges& file, const CopcInfo& info,
                           const std::vector<CopcKey>& keys) {
  const std::string prefix = readPrefix(file);
  std::map<std::tuple<int, int, int, int>, const CopcNode*> by_key;
  for (const CopcNode& node : info.nodes)
    by_key.emplace(std::make_tuple(node.key.depth, node.key.x, node.key.y, node.key.z), &node);
  std::vector<std::string> chunks;
  std::vector<LazChunk> parts;
  chunks.reserve(keys.size());
  for (const CopcKey& key : keys) {
    const auto found = by_key.find(std::make_tuple(key.depth, key.x, key.y, key.z));
    if (found == by_key.end())
      throw pcl::BadArgumentException("no node " + keyName(key) + " in the COPC hierarchy");
    const CopcNode* node = found->second;
    if (node->points == 0) continue;
    chunks.push_back(file.read(node->offset, node->bytes));
    parts.push_back({node->points, chunks.back()});
  }
  return lazToLas(lazOfChunks(prefix, parts), loaderThreads());
}

}  // namespace detail

Eigen::AlignedBox3d CopcInfo::bounds(const CopcKey& key) const {
  const double side = 2.0 * halfsize / std::ldexp(1.0, key.depth);
  const Eigen::Vector3d least =
      center - Eigen::Vector3d::Constant(halfsize) + side * Eigen::Vector3d(key.x, key.y, key.z);
  return {least, least + Eigen::Vector3d::Constant(side)};
}

bool isCopcFile(const std::string& path) {
  detail::FileRanges file(path);
  return detail::isCopc(file);
}

namespace {

/** f(file) on the file at path, its format errors naming the path. */
template <typename F>
auto onFile(const std::string& path, F f) {
  detail::FileRanges file(path);
  try {
    return f(file);
  } catch (const FileFormatException& e) {
    throw FileFormatException(path + ": " + errorDescription(e));
  } catch (const pcl::BadArgumentException& e) {
    throw pcl::BadArgumentException(path + ": " + errorDescription(e));
  }
}

}  // namespace

CopcInfo readCopcInfo(const std::string& path) {
  return onFile(path, [](detail::FileRanges& file) { return detail::readCopcInfo(file); });
}

CopcPoints readCopcNodes(const std::string& path, const std::vector<CopcKey>& keys) {
  return onFile(path, [&](detail::FileRanges& file) {
    const CopcInfo info = detail::readCopcInfo(file);
    return detail::pointsOf(detail::copcNodesAsLas(file, info, keys), file);
  });
}

CopcPoints readCopcBox(const std::string& path, const Eigen::AlignedBox3d& box, int max_depth) {
  return onFile(path, [&](detail::FileRanges& file) {
    const CopcInfo info = detail::readCopcInfo(file);
    std::vector<CopcKey> keys;
    for (const CopcNode& node : info.nodes) {
      if (max_depth >= 0 && node.key.depth > max_depth) continue;
      // A point may lie up to half a scale step outside its node's cube (its coordinates are
      // rounded to the scale): the cubes are widened by a step, the points then kept exactly.
      Eigen::AlignedBox3d cube = info.bounds(node.key);
      cube.min() -= info.scale.cwiseAbs();
      cube.max() += info.scale.cwiseAbs();
      if (node.points > 0 && cube.intersects(box)) keys.push_back(node.key);
    }
    std::string las = detail::copcNodesAsLas(file, info, keys);
    detail::keepRecordsWithin(las, box);
    return detail::pointsOf(las, file);
  });
}

}  // namespace pcl_ddg
