// pcl_ddg_render: a PNG picture of a mesh, coloured by a per-vertex field or its own colours.
#include <pcl/PolygonMesh.h>

#include <array>
#include <iostream>
#include <optional>
#include <string>

#include "common/tool_common.h"
#include "pcl_ddg/features/normal_orientation.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/render/color_bar.h"
#include "pcl_ddg/render/color_map.h"
#include "pcl_ddg/render/mesh_render.h"

namespace {

constexpr const char* kName = "pcl_ddg_render";
constexpr const char* kDescription =
    "Renders a mesh (shaded triangles) or a point cloud (splats, shaded by its normals when it "
    "has\n"
    "them) to a PNG picture, orthographic, coloured by a vertex field or its own colours. A field\n"
    "is coloured between its 2nd and 98th percentiles (symmetric about 0 for -map diverging),\n"
    "values beyond clamped; a colour bar beside the picture gives its name, units and range.";
constexpr const char* kSyntax =
    "input.{ply,obj,off,stl,vtk,pcd,las} output.png [-field name] [-map diverging|sequential]\n"
    "         [-azimuth deg (default 30)] [-elevation deg (default 20)]\n"
    "         [-up x|y|z|-x|-y|-z (default: y as seen from the side that shows the most of the\n"
    "         object, or its largest axis when that side looks along y; z for geographic data)]\n"
    "         [-size pixels]";

// The field's name with its units, for the fields this project's tools write.
std::string withUnits(const std::string& field) {
  if (field == "mean_curvature" || field == "k1" || field == "k2") return field + " [1/length]";
  if (field == "gauss_curvature") return field + " [1/length^2]";
  if (field == "angle_difference") return field + " [deg]";
  return field;
}

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(argc, argv,
                                  {"field", "map", "azimuth", "elevation", "up", "size"}, {});

  RenderOptions options;
  options.width = options.height = args.integer("size", 800);
  if (options.width < 16 || options.width > 8192) throw tools::UsageError("-size must be 16..8192");
  options.azimuth_degrees = args.number("azimuth", options.azimuth_degrees);
  options.elevation_degrees = args.number("elevation", options.elevation_degrees);
  // -up: that axis, viewed from the fixed side; else the view that shows the most of the object.
  const std::optional<std::string> up =
      args.has("up")
          ? std::optional<std::string>(args.choice("up", {"x", "y", "z", "-x", "-y", "-z"}, "y"))
          : std::nullopt;
  if (up) options.up = (up->front() == '-' ? -1.0 : 1.0) * Eigen::Vector3d::Unit(up->back() - 'x');
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
        std::optional<ColorRange> bar;
        if (const auto field = args.value("field")) {
          const Eigen::VectorXd values = vertexScalarField(mesh.cloud, *field);
          bar = colorRange(values, map);
          colors = colorizeWithin(values, map, *bar);
          std::cerr << kName << ": " << *field << " coloured from " << bar->low << " to "
                    << bar->high << " (2nd and 98th percentiles"
                    << (map == ColorMap::Diverging ? ", symmetric about 0" : "")
                    << "); values beyond are clamped\n";
        } else if (vertexColorLayout(mesh.cloud)) {
          colors = vertexColors(mesh.cloud);
        } else {
          colors.setConstant(215);
        }
        const bool geographic = file.las || farFromOrigin(positions);
        RenderOptions view = options;
        Image picture;
        if (mesh.polygons.empty()) {
          // A cloud: splats, shaded by its normals when it has them (either naming).
          Eigen::Matrix3Xd normals;
          for (const auto& names : {std::array<const char*, 3>{"normal_x", "normal_y", "normal_z"},
                                    std::array<const char*, 3>{"nx", "ny", "nz"}}) {
            if (!hasVertexField(mesh.cloud, names[0]) || normals.cols() > 0) continue;
            normals.resize(3, positions.cols());
            for (int d = 0; d < 3; ++d) normals.row(d) = vertexScalarField(mesh.cloud, names[d]);
          }
          if (!args.has("up")) {
            const DefaultView shown = defaultView(positions, normals, geographic);
            view.front = shown.front;
            view.up = shown.up;
          }
          picture = renderPoints(positions, normals, colors, view);
        } else {
          const MeshTopology topology(mesh, OutOfRangeFacePolicy::Drop);
          if (!args.has("up")) {
            const DefaultView shown =
                defaultView(positions, meshOrientationNormals(topology, positions), geographic);
            view.front = shown.front;
            view.up = shown.up;
          }
          picture = renderMesh(positions, topology.triangles(), colors, view);
        }
        if (bar) picture = withColorBar(picture, map, *bar, withUnits(*args.value("field")));
        savePNG(output, picture);
        render_timer.done(static_cast<std::size_t>(positions.cols()));
      });
}

}  // namespace

int main(int argc, char** argv) {
  return pcl_ddg::tools::runTool(kName, kDescription, kSyntax, [&] { return run(argc, argv); });
}
