// pcl_ddg_info: what a mesh or cloud file holds, defects included. It never refuses a file it can
// parse: out-of-range faces, non-finite vertices and the like are counted, not fatal.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string_view>
#include <vector>

#include "common/tool_common.h"
#include "pcl_ddg/io/cloud_pieces.h"
#include "pcl_ddg/io/copc.h"
#include "pcl_ddg/io/las_layout.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/cloud_report.h"
#include "pcl_ddg/mesh/local_cloud.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/result_warnings.h"
#include "pcl_ddg/search/point_spacing.h"

namespace {

constexpr const char* kName = "pcl_ddg_info";
constexpr const char* kDescription =
    "Reports the topology and defects of a mesh (or the layout of a point cloud).";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk,pcd,las,laz} [-json] | -input_dir DIR [-json] (one report per "
    "file)";

const char* asprsClassName(int c) {
  static const char* const kNames[] = {
      "never classified",  "unclassified",    "ground",         "low vegetation",
      "medium vegetation", "high vegetation", "building",       "low point (noise)",
      "model key-point",   "water",           "rail",           "road surface",
      "overlap",           "wire guard",      "wire conductor", "transmission tower",
      "wire connector",    "bridge deck",     "high noise"};
  return c >= 0 && c < 19 ? kNames[c] : "user defined";
}

std::string jsonText(const std::string& text) {
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) quoted += c;
  }
  return quoted + "\"";
}

// An Extra Bytes dimension's name as the file has it (bytes 4-35 of its descriptor).
std::string lasName(const pcl_ddg::LasExtraBytesDimension& d) {
  const std::string name = d.descriptor.substr(4, 32);
  return name.substr(0, name.find('\0'));
}

// The shortest digits that read back as v (a header's doubles, exactly), in fixed notation over
// the range coordinates take (an offset of 5000000, not 5e+06).
std::string number(double v) {
  char text[48];
  const double a = std::abs(v);
  const auto end = a >= 1e-5 && a < 1e15
                       ? std::to_chars(text, text + sizeof text, v, std::chars_format::fixed).ptr
                       : std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

std::string jsonNumber(double v) {
  return std::isfinite(v) ? number(v) : "null";
}

std::string triple(const Eigen::Vector3d& v) {
  return number(v[0]) + " " + number(v[1]) + " " + number(v[2]);
}

// A header bound that differs from the records' by more than half the axis's scale: the two name
// different steps of the integer grid (a writer that took the bound from the records' integers
// differs by nothing).
struct BoundMismatch {
  char axis;
  const char* side;  // "min" or "max"
  double header, records;
};

std::vector<BoundMismatch> boundMismatches(const pcl_ddg::LasLayout& las,
                                           const pcl_ddg::BoundingBox& records) {
  std::vector<BoundMismatch> found;
  for (int d = 0; d < 3; ++d) {
    const char axis = static_cast<char>('x' + d);
    const BoundMismatch sides[] = {{axis, "min", las.min[d], records.min[d]},
                                   {axis, "max", las.max[d], records.max[d]}};
    for (const BoundMismatch& m : sides) {
      if (!(std::abs(m.header - m.records) <= std::abs(las.scale[d]) / 2)) found.push_back(m);
    }
  }
  return found;
}

// A COPC file's octree: its cube, and per level the nodes and points (read by byte ranges: the
// header, VLRs and hierarchy pages again, a few kB).
std::string copcReport(const pcl_ddg::CopcInfo& copc, bool json) {
  std::map<int, std::pair<long long, long long>> levels;  // depth: nodes, points
  for (const pcl_ddg::CopcNode& node : copc.nodes) {
    ++levels[node.key.depth].first;
    levels[node.key.depth].second += node.points;
  }
  std::ostringstream out;
  if (json) {
    out << "{\"center\": [" << jsonNumber(copc.center[0]) << ", " << jsonNumber(copc.center[1])
        << ", " << jsonNumber(copc.center[2]) << "], \"halfsize\": " << jsonNumber(copc.halfsize)
        << ", \"spacing\": " << jsonNumber(copc.spacing) << ", \"nodes\": " << copc.nodes.size()
        << ", \"hierarchy_pages\": " << copc.hierarchy_pages << ", \"levels\": [";
    bool first = true;
    for (const auto& [depth, level] : levels) {
      out << (first ? "" : ", ") << "{\"depth\": " << depth << ", \"nodes\": " << level.first
          << ", \"points\": " << level.second << "}";
      first = false;
    }
    out << "]}";
    return out.str();
  }
  out << "COPC octree:       " << copc.nodes.size() << " nodes in " << levels.size() << " levels, "
      << copc.hierarchy_pages << " hierarchy page" << (copc.hierarchy_pages == 1 ? "" : "s")
      << "; cube centre " << triple(copc.center) << ", half size " << number(copc.halfsize)
      << ", spacing " << number(copc.spacing) << "\n";
  for (const auto& [depth, level] : levels)
    out << "COPC level " << depth << (depth < 10 ? ":      " : ":     ") << level.first
        << (level.first == 1 ? " node, " : " nodes, ") << level.second << " points\n";
  return out.str();
}

// Points per class: of a "classification" field, where the cloud has one.
using Classes = std::map<int, long long>;

void countClasses(const pcl::PCLPointCloud2& cloud, Classes& histogram) {
  const auto field =
      std::find_if(cloud.fields.begin(), cloud.fields.end(),
                   [](const pcl::PCLPointField& f) { return f.name == "classification"; });
  if (field != cloud.fields.end() && field->datatype == pcl::PCLPointField::UINT8) {
    // The LAS reader's byte, counted where it lies (no column of doubles, no map per point).
    std::array<long long, 256> counts{};
    const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
    for (std::size_t i = 0; i < n; ++i) ++counts[cloud.data[i * cloud.point_step + field->offset]];
    for (int c = 0; c < 256; ++c)
      if (counts[c] > 0) histogram[c] += counts[c];
  } else if (field != cloud.fields.end()) {
    const Eigen::VectorXd c = pcl_ddg::vertexScalarField(cloud, "classification");
    for (Eigen::Index i = 0; i < c.size(); ++i) ++histogram[static_cast<int>(c[i])];
  }
}

// A cloud's points, given to `visit` a piece at a time: a whole file's at once, or a file read in
// pieces (each call reads it again).
using PieceVisitor = std::function<void(const pcl_ddg::PositionsRef&)>;
using CloudPass = std::function<void(const PieceVisitor&)>;

struct CloudSummary {
  pcl_ddg::CloudReport report;
  pcl_ddg::PointSpacing spacing;  ///< of the points as floats about their local origin
};

// The report and the spacing the fits would see (floats about the local origin, local_cloud.h),
// in two passes over the points, three when the kd-tree's spacing matters; between them it holds
// 8 bytes a point (the duplicates' hashes), then 12 (the floats' values along each axis).
CloudSummary summarise(std::int64_t width, std::int64_t height, const CloudPass& pass) {
  using namespace pcl_ddg;
  CloudReportBuilder builder(width, height);
  pass([&](const PositionsRef& piece) { builder.count(piece); });
  const Eigen::Vector3d origin = localOrigin(builder.bounds());
  const auto eachLocal = [&](const PositionsRef& piece, const auto& use) {
    for (Eigen::Index i = 0; i < piece.cols(); ++i) {
      const Eigen::Vector3f local = (piece.col(i) - origin).cast<float>();
      if (local.allFinite()) use(local.data());  // finite, and within float's range
    }
  };
  CoordinateValues values;
  values.reserve(static_cast<std::size_t>(builder.finitePoints()));
  pass([&](const PositionsRef& piece) {
    builder.compare(piece);
    eachLocal(piece, [&](const float* p) { values.add(p); });
  });
  CloudSummary summary;
  summary.report = builder.report();
  const bool distinct_possible = values.size() >= 2;
  const CoordinateSpread spread = values.spread();
  values = CoordinateValues();
  summary.spacing.quantum = spread.quantum;
  if (distinct_possible && spread.spacingMatters()) {
    std::vector<float> xyz;
    xyz.reserve(3 * static_cast<std::size_t>(builder.finitePoints()));
    pass([&](const PositionsRef& piece) {
      eachLocal(piece, [&](const float* p) { xyz.insert(xyz.end(), p, p + 3); });
    });
    summary.spacing.median_spacing = medianSpacing(xyz);
  }
  return summary;
}

// What a LAS file holds beside its points: version, point format, scale and offset, the header's
// bounds against the records' (their exact coordinates' box), VLRs, Extra Bytes dimensions and
// the classification histogram; as text lines, or as a JSON object.
std::string lasReport(const std::string& path, const pcl_ddg::LasLayout& las,
                      const Classes& histogram, const pcl_ddg::CloudReport& records, bool json) {
  char head[105] = {};
  std::ifstream(path, std::ios::binary).read(head, sizeof head);
  const bool compressed = pcl_ddg::lasIsCompressed(std::string_view(head, sizeof head));
  // A COPC file whose hierarchy does not hold is still reported on (its points read as LAZ).
  std::optional<pcl_ddg::CopcInfo> copc;
  std::string copc_error;
  try {
    if (compressed && pcl_ddg::isCopcFile(path)) copc = pcl_ddg::readCopcInfo(path);
  } catch (const pcl_ddg::FileFormatException& e) {
    copc_error = pcl_ddg::errorDescription(e);
  }
  const auto record = [](const pcl_ddg::LasVariableLengthRecord& r) {
    return r.userId() + " " + std::to_string(r.record_id) + " (" + std::to_string(r.data.size()) +
           " bytes" + (r.descriptionText().empty() ? "" : ", " + r.descriptionText()) + ")";
  };
  // No records: nothing to compare the header's bounds with.
  const bool compared = records.points > 0;
  const std::vector<BoundMismatch> mismatches =
      compared ? boundMismatches(las, records.bounding_box) : std::vector<BoundMismatch>();
  std::ostringstream out;
  const std::string version =
      std::to_string(las.version_major) + "." + std::to_string(las.version_minor);
  if (json) {
    const auto array = [](const Eigen::Vector3d& v) {
      return "[" + jsonNumber(v[0]) + ", " + jsonNumber(v[1]) + ", " + jsonNumber(v[2]) + "]";
    };
    const char* agree = "null";
    if (compared) agree = mismatches.empty() ? "true" : "false";
    out << "\"las\": {\"storage\": " << (compressed ? "\"laz\"" : "\"las\"") << ", \"copc\": "
        << (copc                 ? copcReport(*copc, true)
            : copc_error.empty() ? std::string("null")
                                 : "{\"error\": " + jsonText(copc_error) + "}")
        << ", \"version\": " << jsonText(version) << ", \"point_format\": " << int(las.point_format)
        << ", \"record_length\": " << las.record_length << ", \"scale\": " << array(las.scale)
        << ", \"offset\": " << array(las.offset) << ", \"header_bounds_min\": " << array(las.min)
        << ", \"header_bounds_max\": " << array(las.max) << ", \"header_bounds_agree\": " << agree
        << ", \"header_bounds_mismatches\": [";
    for (std::size_t k = 0; k < mismatches.size(); ++k) {
      const BoundMismatch& m = mismatches[k];
      out << (k ? ", " : "") << "{\"axis\": \"" << m.axis << "\", \"side\": \"" << m.side
          << "\", \"header\": " << jsonNumber(m.header)
          << ", \"records\": " << jsonNumber(m.records)
          << ", \"difference\": " << jsonNumber(m.header - m.records) << "}";
    }
    out << "], \"vlrs\": [";
    for (std::size_t k = 0; k < las.vlrs.size(); ++k)
      out << (k ? ", " : "") << jsonText(record(las.vlrs[k]));
    out << "], \"evlrs\": [";
    for (std::size_t k = 0; k < las.evlrs.size(); ++k)
      out << (k ? ", " : "") << jsonText(record(las.evlrs[k]));
    out << "], \"extra_bytes\": [";
    for (std::size_t k = 0; k < las.extra_bytes.size(); ++k)
      out << (k ? ", " : "") << jsonText(lasName(las.extra_bytes[k]));
    out << "], \"undocumented_extra_bytes\": " << las.undocumented_bytes
        << ", \"classification\": {";
    bool first = true;
    for (const auto& [c, count] : histogram) {
      out << (first ? "" : ", ") << "\"" << c << "\": " << count;
      first = false;
    }
    out << "}}";
    return out.str();
  }
  out << "LAS:               " << version << ", point format " << int(las.point_format) << " ("
      << las.record_length << "-byte records)" << (compressed ? ", compressed (LAZ)" : "") << "\n"
      << "scale:             " << triple(las.scale) << "\n"
      << "offset:            " << triple(las.offset) << "\n"
      << "header bounds:     [" << triple(las.min) << "] .. [" << triple(las.max) << "]\n";
  if (!compared) {
    out << "header vs records: no records to compare\n";
  } else if (mismatches.empty()) {
    out << "header vs records: agree (within half a scale step)\n";
  }
  for (const BoundMismatch& m : mismatches) {
    out << "header vs records: " << m.axis << " " << m.side << " differs by "
        << number(m.header - m.records) << " (header " << number(m.header) << ", records "
        << number(m.records) << ")\n";
  }
  if (copc) out << copcReport(*copc, false);
  if (!copc_error.empty()) out << "COPC octree:       not read: " << copc_error << "\n";
  for (const auto& r : las.vlrs) out << "VLR:               " << record(r) << "\n";
  for (const auto& r : las.evlrs) out << "EVLR:              " << record(r) << "\n";
  if (!las.extra_bytes.empty()) {
    out << "extra bytes:      ";
    for (const auto& d : las.extra_bytes) out << " " << lasName(d);
    out << "\n";
  }
  if (las.undocumented_bytes > 0)
    out << "undocumented:      " << las.undocumented_bytes << " extra bytes per record\n";
  for (const auto& [c, count] : histogram) {
    char line[96];
    std::snprintf(line, sizeof line, "class %3d:         %lld (%s)\n", c, count, asprsClassName(c));
    out << line;
  }
  return out.str();
}

// Whether a LAS (or LAZ) file declares EVLRs or waveform data (LAS 1.4 R15, table 3: the
// waveform packets' start at byte 227 from 1.3 on, the EVLRs' count at 243 from 1.4 on), which
// the piece reader does not keep and the report lists.
bool lasHasExtendedRecords(const std::string& path) {
  char head[247] = {};
  std::ifstream in(path, std::ios::binary);
  in.read(head, sizeof head);
  if (in.gcount() < 227 || std::string_view(head, 4) != "LASF" || head[24] != 1) return false;
  std::uint64_t waveform = 0;
  std::uint32_t evlrs = 0;
  if (in.gcount() >= 235) std::memcpy(&waveform, head + 227, 8);
  if (in.gcount() >= 247) std::memcpy(&evlrs, head + 243, 4);
  return (head[25] >= 3 && waveform != 0) || (head[25] >= 4 && evlrs != 0);
}

// The points of a file the piece reader takes (binary PCD and PLY clouds, LAS, LAZ with a chunk
// table) a piece at a time, the file read again for each pass: never the whole cloud in memory
// (a 10M-point LAS file: 0.58 of its size, against 3.5 times it read at once). LAZ pieces are
// whole chunks, each decoded once a pass. Null for the other files, read whole, and for LAS files
// with EVLRs (COPC files among them), whose EVLRs only the whole read lists.
std::unique_ptr<pcl_ddg::CloudPieceReader> openPieces(const std::string& path) {
  if (lasHasExtendedRecords(path)) return nullptr;
  try {
    return std::make_unique<pcl_ddg::CloudPieceReader>(path);
  } catch (const pcl_ddg::FileFormatException&) {
    return nullptr;  // read whole: its reader says what is wrong, if anything
  }
}

std::vector<std::pair<std::int64_t, std::int64_t>> piecesOf(pcl_ddg::CloudPieceReader& reader) {
  constexpr std::int64_t kPiece = 1 << 19;
  std::vector<std::pair<std::int64_t, std::int64_t>> pieces;
  const auto chunks = reader.lazChunks();
  if (chunks.empty()) {
    for (std::int64_t first = 0; first < reader.layout().points; first += kPiece)
      pieces.emplace_back(first, std::min(kPiece, reader.layout().points - first));
    return pieces;
  }
  for (const auto& [first, count] : chunks) {
    if (!pieces.empty() && pieces.back().second < kPiece &&
        pieces.back().first + pieces.back().second == first)
      pieces.back().second += count;
    else
      pieces.emplace_back(first, count);
  }
  return pieces;
}

void printCloud(const std::string& path, const CloudSummary& summary, const pcl_ddg::LasLayout* las,
                const Classes& classes, bool json) {
  // The LAS report first: nothing is printed of a file that cannot be reported on.
  const std::string las_text = las ? lasReport(path, *las, classes, summary.report, json) : "";
  if (las && json) {
    std::string text = summary.report.toJson();  // one object: the LAS layout goes inside it
    text.pop_back();
    std::cout << text << ", " << las_text << "}\n";
  } else {
    std::cout << (json ? summary.report.toJson() + "\n" : summary.report.toText()) << las_text;
  }
  if (const auto message = pcl_ddg::quantisationWarning(summary.spacing))
    pcl_ddg::tools::warn(kName, *message);
}

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(argc, argv, {}, {"json"});
  return tools::forEachInput(args, kName, {}, [&](const std::string& path, const std::string&) {
    const bool json = args.has("json");
    // Batch mode's header, once the file is read: nothing is printed of a file that fails.
    const auto header = [&] {
      if (args.has("input_dir") && !json) std::cout << "== " << path << "\n";
    };
    if (const std::unique_ptr<CloudPieceReader> reader = openPieces(path)) {
      tools::Timer timer("Reading " + path + " a piece at a time");
      const auto pieces = piecesOf(*reader);
      Classes classes;
      bool classes_counted = false;
      const CloudSummary summary = summarise(
          reader->layout().width, reader->layout().height, [&](const PieceVisitor& visit) {
            for (const auto& [first, count] : pieces) {
              const CloudPiece piece = reader->read(first, count);
              if (!classes_counted) countClasses(piece.cloud, classes);
              visit(piece.positions);
            }
            classes_counted = true;
          });
      timer.done(static_cast<std::size_t>(summary.report.points));
      header();
      printCloud(path, summary, reader->lasLayout().get(), classes, json);
      return;
    }
    tools::Timer load_timer("Loading " + path);
    // A file of no points is reported on (a LAS file's header), not refused.
    const MeshFile file = readMeshFile(path, EmptyFilePolicy::Accept);
    const pcl::PolygonMesh& mesh = file.mesh;
    load_timer.done(static_cast<std::size_t>(file.positions.cols()));
    if (mesh.polygons.empty()) {
      Classes classes;
      countClasses(mesh.cloud, classes);
      const CloudSummary summary =
          summarise(mesh.cloud.width, mesh.cloud.height,
                    [&](const PieceVisitor& visit) { visit(file.positions); });
      header();
      printCloud(path, summary, file.las.get(), classes, json);
      return;
    }
    const MeshTopology topology(mesh, OutOfRangeFacePolicy::Drop);
    const MeshReport report = makeMeshReport(topology, file.positions);
    header();
    std::cout << (json ? report.toJson() + "\n" : report.toText());
  });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
