// pcl_ddg_info: what a mesh or cloud file holds, defects included. It never refuses a file it can
// parse: out-of-range faces, non-finite vertices and the like are counted, not fatal.
#include <iostream>

#include "common/local_fit_job.h"
#include "common/tool_common.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/cloud_report.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace {

constexpr const char* kName = "pcl_ddg_info";
constexpr const char* kDescription =
    "Reports the topology and defects of a mesh (or the layout of a point cloud).";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk,pcd} [-json] | -input_dir DIR [-json] (one report per file)";

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
      std::cout << (json ? report.toJson() + "\n" : report.toText());
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
