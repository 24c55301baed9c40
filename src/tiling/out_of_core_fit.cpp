#include "pcl_ddg/tiling/out_of_core_fit.h"

#include <fcntl.h>
#include <pcl/exceptions.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/atomic_file.h"

namespace pcl_ddg {
namespace {

[[noreturn]] void failSystem(const std::string& what) {
  throw FileFormatException(what + ": " + std::strerror(errno));
}

// What the search looks in: the float of the point relative to the local origin (as
// makeLocalCloud makes it in memory).
Eigen::Vector3f floatPoint(const Eigen::Vector3d& relative) {
  return relative.cast<float>();
}

// One record per finite point in its tile's file: the point's index in the input, and x, y, z
// relative to the local origin, in double (exact: the fits read them).
struct TileRecord {
  std::int64_t index;
  double xyz[3];
};

class TileFiles {
 public:
  TileFiles(std::string folder, std::size_t tiles, std::size_t buffer_records)
      : folder_(std::move(folder)), buffers_(tiles), buffer_records_(buffer_records) {}

  void add(int tile, std::int64_t index, const Eigen::Vector3d& p) {
    auto& buffer = buffers_[tile];
    buffer.push_back({index, {p.x(), p.y(), p.z()}});
    if (buffer.size() >= buffer_records_) flush(tile);
  }
  void flushAll() {
    for (std::size_t t = 0; t < buffers_.size(); ++t) flush(static_cast<int>(t));
  }
  std::vector<TileRecord> read(int tile) const {
    std::ifstream in(path(tile), std::ios::binary);
    std::vector<TileRecord> records;
    if (!in) return records;  // no point was written for it
    in.seekg(0, std::ios::end);
    records.resize(static_cast<std::size_t>(in.tellg()) / sizeof(TileRecord));
    in.seekg(0);
    in.read(reinterpret_cast<char*>(records.data()),
            static_cast<std::streamsize>(records.size() * sizeof(TileRecord)));
    if (!in) failSystem("cannot read " + path(tile));
    return records;
  }

 private:
  std::string path(int tile) const { return folder_ + "/tile_" + std::to_string(tile) + ".bin"; }
  void flush(int tile) {
    auto& buffer = buffers_[tile];
    if (buffer.empty()) return;
    std::ofstream out(path(tile), std::ios::binary | std::ios::app);
    out.write(reinterpret_cast<const char*>(buffer.data()),
              static_cast<std::streamsize>(buffer.size() * sizeof(TileRecord)));
    if (!out) failSystem("cannot write " + path(tile));
    buffer.clear();
  }

  std::string folder_;
  std::vector<std::vector<TileRecord>> buffers_;
  std::size_t buffer_records_;
};

// The fit of every point at its place: normal x y z, curvature, and for the quadric pc1, pc2 and
// the k1 direction, for robust the scale and confidence; NaN until written.
class ResultFile {
 public:
  ResultFile(const std::string& path, std::int64_t points, LocalFitMethod method)
      : floats_(method == LocalFitMethod::Quadric  ? 9
                : method == LocalFitMethod::Robust ? 6
                                                   : 4) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0600);
    if (fd_ < 0) failSystem("cannot create " + path);
    const std::vector<float> nan(static_cast<std::size_t>(floats_) * 65536,
                                 std::numeric_limits<float>::quiet_NaN());
    for (std::int64_t i = 0; i < points; i += 65536) {
      const std::int64_t n = std::min<std::int64_t>(65536, points - i);
      writeAt(i, nan.data(), n);
    }
  }
  ~ResultFile() { ::close(fd_); }
  ResultFile(const ResultFile&) = delete;
  ResultFile& operator=(const ResultFile&) = delete;

  /** Writes the fit of the points `positions` (into the fit's order) whose indices in the input
   *  are `global` (ascending): one write per run of consecutive indices, not one per point. */
  void put(const std::vector<std::int64_t>& global, const pcl::Indices& positions,
           const LocalFitResult& fit) {
    std::vector<float> run;
    std::int64_t run_first = 0;
    for (std::size_t j = 0; j < positions.size(); ++j) {
      const std::int64_t point = global[positions[j]];
      if (!run.empty() && point != run_first + static_cast<std::int64_t>(run.size()) / floats_) {
        writeAt(run_first, run.data(), static_cast<std::int64_t>(run.size()) / floats_);
        run.clear();
      }
      if (run.empty()) run_first = point;
      const pcl::Normal& n = fit.normals[j];
      run.insert(run.end(), {n.normal_x, n.normal_y, n.normal_z, n.curvature});
      if (floats_ == 6) run.insert(run.end(), {fit.scales[j], fit.confidences[j]});
      if (floats_ == 9) {
        const pcl::PrincipalCurvatures& c = fit.curvatures[j];
        run.insert(run.end(), {c.pc1, c.pc2, c.principal_curvature_x, c.principal_curvature_y,
                               c.principal_curvature_z});
      }
    }
    if (!run.empty())
      writeAt(run_first, run.data(), static_cast<std::int64_t>(run.size()) / floats_);
  }

  /** The results of points [first, first + count) as a fit of that piece. */
  LocalFitResult get(std::int64_t first, std::int64_t count) const {
    std::vector<float> records(static_cast<std::size_t>(count * floats_));
    const std::size_t bytes = records.size() * sizeof(float);
    if (::pread(fd_, records.data(), bytes, first * floats_ * 4) != static_cast<ssize_t>(bytes))
      failSystem("cannot read the results");
    LocalFitResult fit;
    fit.normals.resize(static_cast<std::size_t>(count));
    if (floats_ == 9) fit.curvatures.resize(static_cast<std::size_t>(count));
    if (floats_ == 6) {
      fit.scales.resize(static_cast<std::size_t>(count));
      fit.confidences.resize(static_cast<std::size_t>(count));
    }
    for (std::int64_t i = 0; i < count; ++i) {
      const float* r = records.data() + i * floats_;
      pcl::Normal& n = fit.normals[i];
      n.normal_x = r[0];
      n.normal_y = r[1];
      n.normal_z = r[2];
      n.curvature = r[3];
      if (floats_ == 6) {
        fit.scales[i] = r[4];
        fit.confidences[i] = r[5];
      }
      if (floats_ == 9) {
        pcl::PrincipalCurvatures& c = fit.curvatures[i];
        c.pc1 = r[4];
        c.pc2 = r[5];
        c.principal_curvature_x = r[6];
        c.principal_curvature_y = r[7];
        c.principal_curvature_z = r[8];
      }
    }
    return fit;
  }

 private:
  void writeAt(std::int64_t point, const float* values, std::int64_t count) {
    const std::size_t bytes = static_cast<std::size_t>(count * floats_) * sizeof(float);
    if (::pwrite(fd_, values, bytes, point * floats_ * 4) != static_cast<ssize_t>(bytes))
      failSystem("cannot write the results");
  }

  int fd_ = -1;
  int floats_;
};

// A folder of our own for the tile files, removed however the run ends.
class ScratchFolder {
 public:
  explicit ScratchFolder(const std::string& parent) {
    std::string name = (parent.empty() ? std::string(".") : parent) + "/.pcl_ddg_tiles_XXXXXX";
    if (!::mkdtemp(name.data())) failSystem("cannot create a scratch folder in " + parent);
    path_ = name;
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

OutOfCoreReport fitCloudFileOutOfCore(const std::string& input, const std::string& output,
                                      LocalFitOptions options, const OutOfCoreOptions& limits,
                                      const ResultFields& add_fields) {
  if (options.neighbourhood != NeighbourhoodKind::KdTree)
    throw pcl::BadArgumentException("a cloud out of core is fitted with kd-tree neighbourhoods");
  const std::string output_format = fileExtension(output);
  if (output_format != "ply" && output_format != "pcd" && output_format != "las" &&
      output_format != "laz")
    throw FileFormatException(output + ": the output must be .ply, .pcd, .las or .laz");
  CloudPieceReader pieces(input);
  if ((output_format == "las" || output_format == "laz") && !pieces.lasLayout())
    throw FileFormatException(output + ": a ." + output_format +
                              " output out of core needs a .las or .laz input (its layout)");
  if (output_format == "laz" && !lazCompressible(pieces.lasLayout()->point_format))
    throw FileFormatException(output + ": point format " +
                              std::to_string(pieces.lasLayout()->point_format) +
                              " cannot be written as LAZ (formats 0-3 and 6-8 can): write .las");
  const CloudFileLayout& layout = pieces.layout();
  OutOfCoreReport report;
  report.points = layout.points;
  report.sensor_pose = layout.sensor_pose;
  if (!options.viewpoint) options.viewpoint = layout.sensor_pose.origin;
  if (layout.points == 0) throw FileFormatException(input + ": no points (the header counts none)");
  if (options.radius == 0.0 && options.k > layout.points)
    throw pcl::BadArgumentException("k is more than the " + std::to_string(layout.points) +
                                    " points of the input");
  // About 400 bytes per own point at once: the point, its index, two kd-trees, the halo's share,
  // the fit's output; a piece of the file costs its records and their parsed copy.
  report.points_per_tile = static_cast<std::int64_t>(limits.memory_budget / 400);
  report.points_per_piece = std::clamp<std::int64_t>(
      static_cast<std::int64_t>(limits.memory_budget / 8 / (layout.point_bytes * 3 + 64)), 1024,
      std::int64_t{1} << 22);
  if (report.points_per_tile < 4096)
    throw pcl::BadArgumentException("a memory budget of at least 2M is needed");
  const auto forEachPiece = [&](const std::function<void(std::int64_t, CloudPiece&)>& visit) {
    for (std::int64_t first = 0; first < layout.points; first += report.points_per_piece) {
      CloudPiece piece =
          pieces.read(first, std::min(report.points_per_piece, layout.points - first));
      visit(first, piece);
    }
  };

  // 1. Bounds of the finite points, for the local origin (local_cloud.h: the rule the cloud in
  // memory follows) and the plan, which is cut from the points' floats relative to it (rounding
  // is monotonic: their bounds are the rounded bounds).
  Eigen::AlignedBox3d world_bounds;
  forEachPiece([&](std::int64_t, CloudPiece& piece) {
    for (Eigen::Index i = 0; i < piece.positions.cols(); ++i) {
      if (piece.positions.col(i).allFinite())
        world_bounds.extend(piece.positions.col(i));
      else
        ++report.failed_points;
    }
  });
  const Eigen::Vector3d origin = localOrigin(world_bounds);
  Eigen::AlignedBox3d bounds;
  if (!world_bounds.isEmpty()) {
    const Eigen::Vector3d low = world_bounds.min() - origin, high = world_bounds.max() - origin;
    if (std::max(low.cwiseAbs().maxCoeff(), high.cwiseAbs().maxCoeff()) >
        std::numeric_limits<float>::max())
      throw FileFormatException(input +
                                ": the points span more than float's range (PCL's "
                                "point types are float)");
    bounds.extend(floatPoint(low).cast<double>());
    bounds.extend(floatPoint(high).cast<double>());
  }

  const std::string folder = limits.scratch_folder.empty()
                                 ? std::filesystem::path(output).parent_path().string()
                                 : limits.scratch_folder;
  const ScratchFolder scratch(folder);
  ResultFile results(scratch.path() + "/results.bin", layout.points, options.method);
  if (!bounds.isEmpty()) {
    // 2. The plan, from a histogram of a second pass.
    PointHistogram histogram(bounds, 128);
    forEachPiece([&](std::int64_t, CloudPiece& piece) {
      for (Eigen::Index i = 0; i < piece.positions.cols(); ++i) {
        const Eigen::Vector3f p = floatPoint(piece.positions.col(i) - origin);
        if (p.allFinite()) histogram.add(p.cast<double>());
      }
    });
    const TilePlan plan = planTiles(histogram, report.points_per_tile);
    std::ofstream(scratch.path() + "/plan.json") << plan.toJson() << "\n";

    // 3. Every point into its tile's file.
    const std::size_t buffer_records = std::clamp<std::size_t>(
        limits.memory_budget / 8 / sizeof(TileRecord) / plan.tiles.size(), 256, 65536);
    TileFiles tiles(scratch.path(), plan.tiles.size(), buffer_records);
    forEachPiece([&](std::int64_t first, CloudPiece& piece) {
      for (Eigen::Index i = 0; i < piece.positions.cols(); ++i) {
        const Eigen::Vector3d relative = piece.positions.col(i) - origin;
        const Eigen::Vector3f p = floatPoint(relative);
        if (p.allFinite()) tiles.add(plan.tileOf(p.cast<double>()), first + i, relative);
      }
    });
    tiles.flushAll();

    // 4. Each tile with its halo, gathered from the tile files it touches.
    const auto gather = [&](int tile, const Eigen::AlignedBox3d& region) {
      TilePoints points;
      points.points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
      points.own = std::make_shared<pcl::Indices>();
      points.origin = origin;
      std::vector<std::pair<std::int64_t, Eigen::Vector3d>> gathered;
      std::vector<char> own_flags;
      for (int t = 0; t < static_cast<int>(plan.tiles.size()); ++t) {
        if (t != tile && !plan.tiles[t].box.intersects(region)) continue;
        for (const TileRecord& r : tiles.read(t)) {
          const Eigen::Vector3d relative(r.xyz[0], r.xyz[1], r.xyz[2]);
          if (t != tile && !region.contains(floatPoint(relative).cast<double>())) continue;
          gathered.emplace_back(r.index, relative);
          own_flags.push_back(t == tile);
        }
      }
      // In the input's order, as the whole cloud is indexed.
      std::vector<std::size_t> order(gathered.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return gathered[a].first < gathered[b].first;
      });
      points.points->resize(order.size());
      points.positions = std::make_shared<Eigen::Matrix3Xd>(3, order.size());
      for (std::size_t j = 0; j < order.size(); ++j) {
        const std::size_t i = order[j];
        if (own_flags[i]) points.own->push_back(static_cast<pcl::index_t>(j));
        (*points.points)[j].getVector3fMap() = floatPoint(gathered[i].second);
        points.positions->col(static_cast<Eigen::Index>(j)) = gathered[i].second;
        points.global_index.push_back(gathered[i].first);
      }
      return points;
    };
    const auto consume = [&](const TilePoints& points, const LocalFitResult& fit) {
      results.put(points.global_index, *points.own, fit);
      report.failed_points += fit.failed_points;
      report.fallback_points += fit.fallback_points;
    };
    fitTiles(plan, options, gather, consume, &report.tiling);
  }

  // 5. The input's pieces with the results beside them.
  AtomicFile file(output);
  CloudPieceWriter out(file.temporaryPath(), output_format, layout.points, layout.width,
                       layout.height, layout.sensor_pose, pieces.lasLayout());
  forEachPiece([&](std::int64_t first, CloudPiece& piece) {
    add_fields(piece, results.get(first, piece.positions.cols()));
    out.write(piece.cloud);
  });
  out.close();
  file.commit();
  return report;
}

}  // namespace pcl_ddg
