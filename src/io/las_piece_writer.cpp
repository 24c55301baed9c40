// The out-of-core LAS writer (LasPieceWriter): a file written a piece of points at a time by
// the plan of the first piece's fields, the header's counts and bounds written at close().
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "las_format.h"
#include "las_write.h"
#include "pcl_ddg/exceptions.h"

namespace pcl_ddg {
namespace detail {

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
