// pcl_ddg_render: a PNG picture of a mesh, coloured by a per-vertex field or its own colours.
#include <pcl/PolygonMesh.h>

#include <array>

#include "common/tool_common.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/render/color_map.h"
#include "pcl_ddg/render/mesh_render.h"

namespace {

constexpr const char* kName = "pcl_ddg_render";
constexpr const char* kDescription =
    "Renders a mesh (shaded triangles) or a point cloud (splats, shaded by its normals when it "
    "has\n"
    "them) to a PNG picture, orthographic, coloured by a vertex field or its own colours.";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk,pcd} output.png [-field name] [-map diverging|sequential]\n"
    "         [-azimuth deg] [-elevation deg] [-up x|y|z] [-size pixels]";

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(argc, argv,
                                  {"field", "map", "azimuth", "elevation", "up", "size"}, {});

  RenderOptions options;
  options.width = options.height = args.integer("size", 800);
  if (options.width < 16 || options.width > 8192) throw tools::UsageError("-size must be 16..8192");
  options.azimuth_degrees = args.number("azimuth", options.azimuth_degrees);
  options.elevation_degrees = args.number("elevation", options.elevation_degrees);
  const std::string up = args.choice("up", {"x", "y", "z"}, "y");
  options.up = Eigen::Vector3d::Unit(up[0] - 'x');
  const ColorMap map = args.choice("map", {"diverging", "sequential"}, "diverging") == "diverging"
                           ? ColorMap::Diverging
                           : ColorMap::Sequential;

  return tools::forEachInput(
      args, kName, {"png"}, [&](const std::string& input, const std::string& output) {
        tools::Timer load_timer("Loading " + input);
        const MeshFile file = readMeshFile(input);
        const pcl::PolygonMesh& mesh = file.mesh;
        load_timer.done(static_cast<std::size_t>(file.positions.cols()));
        tools::Timer render_timer("Rendering " + output);
        const Eigen::Matrix3Xd& positions = file.positions;
        VertexColors colors(3, positions.cols());
        if (const auto field = args.value("field")) {
          colors = colorize(vertexScalarField(mesh.cloud, *field), map);
        } else if (vertexColorLayout(mesh.cloud)) {
          colors = vertexColors(mesh.cloud);
        } else {
          colors.setConstant(215);
        }
        if (mesh.polygons.empty()) {
          // A cloud: splats, shaded by its normals when it has them (either naming).
          Eigen::Matrix3Xd normals;
          for (const auto& names : {std::array<const char*, 3>{"normal_x", "normal_y", "normal_z"},
                                    std::array<const char*, 3>{"nx", "ny", "nz"}}) {
            if (!hasVertexField(mesh.cloud, names[0]) || normals.cols() > 0) continue;
            normals.resize(3, positions.cols());
            for (int d = 0; d < 3; ++d) normals.row(d) = vertexScalarField(mesh.cloud, names[d]);
          }
          savePNG(output, renderPoints(positions, normals, colors, options));
        } else {
          const MeshTopology topology(mesh, OutOfRangeFacePolicy::Drop);
          savePNG(output, renderMesh(positions, topology.triangles(), colors, options));
        }
        render_timer.done(static_cast<std::size_t>(positions.cols()));
      });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
