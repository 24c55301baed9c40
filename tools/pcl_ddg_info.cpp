// pcl_ddg_info: what a mesh or cloud file holds, defects included. It never refuses a file it can
// parse: out-of-range faces, non-finite vertices and the like are counted, not fatal.
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>

#include "common/fit_steps.h"
#include "common/tool_common.h"
#include "common/tool_input.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/cloud_report.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace {

constexpr const char* kName = "pcl_ddg_info";
constexpr const char* kDescription =
    "Reports the topology and defects of a mesh (or the layout of a point cloud).";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk,pcd,las} [-json] | -input_dir DIR [-json] (one report per file)";

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

std::string number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

// What a LAS file holds beside its points: version, point format, scale and offset, VLRs, Extra
// Bytes dimensions and the classification histogram; as text lines, or as a JSON object.
std::string lasReport(const pcl_ddg::LasLayout& las, const pcl::PCLPointCloud2& cloud, bool json) {
  std::map<int, long long> histogram;
  if (pcl_ddg::hasVertexField(cloud, "classification")) {
    const Eigen::VectorXd c = pcl_ddg::vertexScalarField(cloud, "classification");
    for (Eigen::Index i = 0; i < c.size(); ++i) ++histogram[static_cast<int>(c[i])];
  }
  const auto record = [](const pcl_ddg::LasVariableLengthRecord& r) {
    return r.userId() + " " + std::to_string(r.record_id) + " (" + std::to_string(r.data.size()) +
           " bytes" + (r.descriptionText().empty() ? "" : ", " + r.descriptionText()) + ")";
  };
  std::ostringstream out;
  const std::string version =
      std::to_string(las.version_major) + "." + std::to_string(las.version_minor);
  if (json) {
    out << "\"las\": {\"version\": " << jsonText(version)
        << ", \"point_format\": " << int(las.point_format)
        << ", \"record_length\": " << las.record_length << ", \"scale\": [" << number(las.scale[0])
        << ", " << number(las.scale[1]) << ", " << number(las.scale[2]) << "], \"offset\": ["
        << number(las.offset[0]) << ", " << number(las.offset[1]) << ", " << number(las.offset[2])
        << "], \"vlrs\": [";
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
      << las.record_length << "-byte records)\n"
      << "scale:             " << number(las.scale[0]) << " " << number(las.scale[1]) << " "
      << number(las.scale[2]) << "\n"
      << "offset:            " << number(las.offset[0]) << " " << number(las.offset[1]) << " "
      << number(las.offset[2]) << "\n";
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

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(argc, argv, {}, {"json"});
  return tools::forEachInput(args, kName, {}, [&](const std::string& path, const std::string&) {
    tools::Timer load_timer("Loading " + path);
    const MeshFile file = readMeshFile(path);
    const pcl::PolygonMesh& mesh = file.mesh;
    load_timer.done(static_cast<std::size_t>(file.positions.cols()));

    const bool json = args.has("json");
    if (args.has("input_dir") && !json) std::cout << "== " << path << "\n";
    if (mesh.polygons.empty()) {
      const CloudReport report = makeCloudReport(mesh.cloud);
      if (file.las && json) {
        std::string text = report.toJson();  // one object: the LAS layout goes inside it
        text.pop_back();
        std::cout << text << ", " << lasReport(*file.las, mesh.cloud, true) << "}\n";
      } else {
        std::cout << (json ? report.toJson() + "\n" : report.toText());
        if (file.las) std::cout << lasReport(*file.las, mesh.cloud, false);
      }
      tools::warnAboutQuantisation(kName, *tools::toXYZ(file.positions));
      return;
    }
    const MeshTopology topology(mesh, OutOfRangeFacePolicy::Drop);
    const MeshReport report = makeMeshReport(topology, file.positions);
    std::cout << (json ? report.toJson() + "\n" : report.toText());
  });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
