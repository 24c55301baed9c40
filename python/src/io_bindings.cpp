// Files: read and write every format the tools handle, through the library's io (mesh_io.h). The
// coordinates come as the file holds them (double where it stores doubles); every other vertex
// field in its own type; colours as uint8 (n, 3).
#include <pcl/PCLPointField.h>
#include <pcl/PolygonMesh.h>
#include <pcl/common/io.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>

#include "binding_common.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/cloud_pieces.h"
#include "pcl_ddg/io/copc.h"
#include "pcl_ddg/io/las_layout.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"

namespace pcl_ddg {
namespace python {

namespace {

py::dtype dtypeOf(std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
      return py::dtype::of<std::int8_t>();
    case pcl::PCLPointField::UINT8:
      return py::dtype::of<std::uint8_t>();
    case pcl::PCLPointField::INT16:
      return py::dtype::of<std::int16_t>();
    case pcl::PCLPointField::UINT16:
      return py::dtype::of<std::uint16_t>();
    case pcl::PCLPointField::INT32:
      return py::dtype::of<std::int32_t>();
    case pcl::PCLPointField::UINT32:
      return py::dtype::of<std::uint32_t>();
    case pcl::PCLPointField::INT64:
      return py::dtype::of<std::int64_t>();
    case pcl::PCLPointField::UINT64:
      return py::dtype::of<std::uint64_t>();
    case pcl::PCLPointField::FLOAT32:
      return py::dtype::of<float>();
    case pcl::PCLPointField::FLOAT64:
      return py::dtype::of<double>();
    default:
      throw std::runtime_error("unknown PCL field type " + std::to_string(datatype));
  }
}

// One field of every point as an (n,) or (n, count) array of its own type.
py::array fieldArray(const pcl::PCLPointCloud2& cloud, const pcl::PCLPointField& field) {
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  const py::dtype dtype = dtypeOf(field.datatype);
  const auto size = static_cast<std::size_t>(dtype.itemsize());
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(n)};
  if (field.count > 1) shape.push_back(field.count);
  py::array out(dtype, shape);
  auto* dst = static_cast<std::uint8_t*>(out.mutable_data());
  const std::size_t bytes = size * std::max<std::uint32_t>(field.count, 1);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t row = i / cloud.width, column = i % cloud.width;
    std::memcpy(dst + i * bytes,
                cloud.data.data() + row * cloud.row_step + column * cloud.point_step + field.offset,
                bytes);
  }
  return out;
}

py::object facesOf(const std::vector<pcl::Vertices>& polygons) {
  const bool triangles = std::all_of(polygons.begin(), polygons.end(),
                                     [](const pcl::Vertices& p) { return p.vertices.size() == 3; });
  if (triangles) {
    py::array_t<std::int32_t> faces({static_cast<py::ssize_t>(polygons.size()), py::ssize_t{3}});
    std::int32_t* out = faces.mutable_data();
    for (std::size_t t = 0; t < polygons.size(); ++t) {
      for (int c = 0; c < 3; ++c)
        out[3 * t + c] = static_cast<std::int32_t>(polygons[t].vertices[c]);
    }
    return std::move(faces);
  }
  py::list faces;
  for (const pcl::Vertices& p : polygons) {
    py::array_t<std::int32_t> polygon(static_cast<py::ssize_t>(p.vertices.size()));
    std::copy(p.vertices.begin(), p.vertices.end(), polygon.mutable_data());
    faces.append(polygon);
  }
  return std::move(faces);
}

// Every value of a float64 array survives the cast to float (NaN and infinities included).
bool fitsFloat(const Eigen::Ref<const Eigen::MatrixXd>& values) {
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const double v = values.data()[i];
    if (!std::isnan(v) && static_cast<double>(static_cast<float>(v)) != v) return false;
  }
  return true;
}

FieldPrecision precisionOf(const std::optional<std::string>& precision, const py::dtype& dtype,
                           const Eigen::Ref<const Eigen::MatrixXd>& values) {
  if (precision)
    return choice("precision", *precision, {"float", "double"}) == "double" ? FieldPrecision::Double
                                                                            : FieldPrecision::Float;
  // Unset: lossless, float when it holds every value.
  return dtype.kind() == 'f' && dtype.itemsize() == 8 && !fitsFloat(values) ? FieldPrecision::Double
                                                                            : FieldPrecision::Float;
}

// An (m, k) face array as one block of rows, its indices checked without the GIL (no topology
// is built: the file holds the faces as given).
std::shared_ptr<const FaceRows> faceRowsOf(int n, const py::array& faces) {
  const auto indices = faceRows(faces);
  auto rows = std::make_shared<FaceRows>();
  rows->corners = static_cast<std::size_t>(indices.shape(1));
  const std::size_t size = static_cast<std::size_t>(indices.shape(0)) * rows->corners;
  const long long* data = indices.data();
  std::size_t bad = size;
  {
    py::gil_scoped_release release;
    rows->indices.resize(size);
    for (std::size_t j = 0; j < size; ++j) {
      if (data[j] < 0 || data[j] >= n) {
        bad = j;
        break;
      }
      rows->indices[j] = static_cast<std::int32_t>(data[j]);
    }
  }
  if (bad < size) checkedIndex(data[bad], n, bad / rows->corners);  // throws ValueError
  return rows;
}

// A list of polygons, checked as every mesh function checks it, then written as given.
std::vector<pcl::Vertices> polygonsOf(int n, const py::object& faces) {
  topologyOf(n, faces);
  std::vector<pcl::Vertices> polygons;
  for (const py::handle polygon : faces) {
    const auto p = py::array_t<long long, py::array::forcecast>::ensure(polygon);
    polygons.emplace_back();
    polygons.back().vertices.assign(p.data(), p.data() + p.size());
  }
  return polygons;
}

// The PCL type of a numpy dtype (bool as UINT8); 0 if it has none.
std::uint8_t pclTypeOf(const py::dtype& dtype) {
  const char kind = dtype.kind();
  const auto size = dtype.itemsize();
  if (kind == 'b') return pcl::PCLPointField::UINT8;
  if (kind == 'f')
    return size == 4 ? pcl::PCLPointField::FLOAT32 : size == 8 ? pcl::PCLPointField::FLOAT64 : 0;
  if (kind == 'i' || kind == 'u') {
    const bool u = kind == 'u';
    switch (size) {
      case 1:
        return u ? pcl::PCLPointField::UINT8 : pcl::PCLPointField::INT8;
      case 2:
        return u ? pcl::PCLPointField::UINT16 : pcl::PCLPointField::INT16;
      case 4:
        return u ? pcl::PCLPointField::UINT32 : pcl::PCLPointField::INT32;
      case 8:
        return u ? pcl::PCLPointField::UINT64 : pcl::PCLPointField::INT64;
      default:
        return 0;
    }
  }
  return 0;
}

// A field appended in its own type: (n,) or (n, count) values, C-contiguous.
struct TypedField {
  std::string name;
  std::uint8_t datatype;
  std::uint32_t count;
  py::array values;
};

// Appends the fields to an unorganized cloud (one repacking of every point).
void appendTypedFields(pcl::PCLPointCloud2& cloud, const std::vector<TypedField>& fields) {
  if (fields.empty()) return;
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  std::uint32_t step = cloud.point_step;
  std::vector<std::uint32_t> offsets;
  for (const TypedField& f : fields) {
    pcl::PCLPointField field;
    field.name = f.name;
    field.offset = step;
    field.datatype = f.datatype;
    field.count = f.count;
    cloud.fields.push_back(field);
    offsets.push_back(step);
    step += static_cast<std::uint32_t>(pcl::getFieldSize(f.datatype)) * f.count;
  }
  std::vector<std::uint8_t> data(n * step);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t row = i / cloud.width, column = i % cloud.width;
    std::memcpy(data.data() + i * step,
                cloud.data.data() + row * cloud.row_step + column * cloud.point_step,
                cloud.point_step);
  }
  for (std::size_t k = 0; k < fields.size(); ++k) {
    const std::size_t bytes = pcl::getFieldSize(fields[k].datatype) * fields[k].count;
    const auto* src = static_cast<const std::uint8_t*>(fields[k].values.data());
    for (std::size_t i = 0; i < n; ++i)
      std::memcpy(data.data() + i * step + offsets[k], src + i * bytes, bytes);
  }
  cloud.data = std::move(data);
  cloud.point_step = step;
  cloud.row_step = step * cloud.width;
}

py::bytes bytesOf(const std::string& s) {
  return py::bytes(s.data(), s.size());
}

py::tuple vector3(const Eigen::Vector3d& v) {
  return py::make_tuple(v.x(), v.y(), v.z());
}

py::list recordsOf(const std::vector<LasVariableLengthRecord>& records) {
  py::list out;
  for (const LasVariableLengthRecord& r : records)
    out.append(py::make_tuple(r.userId(), r.record_id, r.descriptionText(), bytesOf(r.data)));
  return out;
}

// A LAS file's header and VLRs, read (no point) by the reader the Dask runner reads its chunks
// with (CloudPieceReader: the library's LAS parser), for pcl_ddg.distributed's checks of the
// inputs of one scene. A LAZ file (a LAS header whose point format has the compression bits set,
// or one named .laz) is reported, {"compressed": True}, not refused: the runner names it with
// how to decompress it, once every input's header is read.
py::dict lasHeader(const std::string& path) {
  CloudFileLayout file;
  std::shared_ptr<const LasLayout> las;
  bool compressed = false;
  {
    py::gil_scoped_release release;
    std::string head(227, '\0');  // a LAS 1.0 header, as CloudPieceReader tells a LAS file
    std::ifstream in(path, std::ios::binary);
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    compressed = in.gcount() == static_cast<std::streamsize>(head.size()) &&
                 head.compare(0, 4, "LASF") == 0 && lasIsCompressed(head);
    CloudPieceReader pieces(path);  // LAZ: the header of the LAS file it stands for
    file = pieces.layout();
    las = pieces.lasLayout();
    if (las == nullptr) throw FileFormatException(path + ": not a LAS file (no LASF signature)");
  }
  py::dict d;
  d["compressed"] = compressed;
  d["version"] = std::to_string(las->version_major) + "." + std::to_string(las->version_minor);
  d["point_format"] = las->point_format;
  d["record_length"] = las->record_length;
  d["points"] = file.points;
  d["scale"] = vector3(las->scale);
  d["offset"] = vector3(las->offset);
  d["bounds"] = py::make_tuple(las->min.x(), las->min.y(), las->min.z(), las->max.x(), las->max.y(),
                               las->max.z());
  d["data_offset"] = file.header_bytes;
  py::list vlrs;
  for (const LasVariableLengthRecord& r : las->vlrs)
    vlrs.append(py::make_tuple(bytesOf(r.userId()), r.record_id, bytesOf(r.data)));
  d["vlrs"] = vlrs;
  return d;
}

/** read's tuple of a file read: (points, faces, fields, viewpoint, orientation, organized_shape,
 *  precision, las). */
py::tuple meshFileTuple(MeshFile&& file) {
  const pcl::PCLPointCloud2& cloud = file.mesh.cloud;
  py::dict fields;
  // LAS: every field as stored (red green blue stay uint16, so that write gives them back).
  const bool colours = !file.las && vertexColorLayout(cloud).has_value();
  const std::set<std::string> coordinates = {"x", "y", "z", "_"};
  const std::set<std::string> colour_fields = {"rgb", "rgba", "red", "green", "blue", "alpha"};
  for (const pcl::PCLPointField& field : cloud.fields) {
    if (coordinates.count(field.name) != 0) continue;
    if (colours && colour_fields.count(field.name) != 0) continue;  // as "rgb" (n, 3)
    fields[py::str(field.name)] = fieldArray(cloud, field);
  }
  if (colours) {
    const VertexColors rgb = vertexColors(cloud);
    py::array_t<std::uint8_t> array({static_cast<py::ssize_t>(rgb.cols()), py::ssize_t{3}});
    std::memcpy(array.mutable_data(), rgb.data(), static_cast<std::size_t>(rgb.size()));
    fields["rgb"] = array;
  }
  const py::object faces =
      file.mesh.polygons.empty() ? py::object(py::none()) : facesOf(file.mesh.polygons);
  const Eigen::Quaterniond& q = file.sensor_pose.orientation;
  const py::object shape = cloud.height > 1 ? py::object(py::make_tuple(cloud.height, cloud.width))
                                            : py::object(py::none());
  const Eigen::Vector3d origin = file.sensor_pose.origin;
  return py::make_tuple(
      rowsArray(std::move(file.positions)), faces, fields,
      py::make_tuple(origin.x(), origin.y(), origin.z()),
      py::make_tuple(q.w(), q.x(), q.y(), q.z()), shape,
      file.coordinate_precision == FieldPrecision::Double ? "double" : "float",
      file.las ? py::cast(std::const_pointer_cast<LasLayout>(file.las)) : py::object(py::none()));
}

}  // namespace

void bindIO(py::module_& m) {
  py::class_<LasLayout, std::shared_ptr<LasLayout>>(
      m, "LasLayout",
      "A LAS file's layout as read (version, point format, scale and offset, VLRs, Extra Bytes): "
      "passed back to write, a .las output keeps it.")
      .def_property_readonly(
          "version",
          [](const LasLayout& l) { return py::make_tuple(l.version_major, l.version_minor); })
      .def_readonly("point_format", &LasLayout::point_format)
      .def_readonly("record_length", &LasLayout::record_length)
      .def_readonly("point_count", &LasLayout::point_count)
      .def_readonly("file_source_id", &LasLayout::file_source_id)
      .def_readonly("global_encoding", &LasLayout::global_encoding)
      .def_property_readonly("scale", [](const LasLayout& l) { return vector3(l.scale); })
      .def_property_readonly("offset", [](const LasLayout& l) { return vector3(l.offset); })
      .def_property_readonly("min", [](const LasLayout& l) { return vector3(l.min); })
      .def_property_readonly("max", [](const LasLayout& l) { return vector3(l.max); })
      .def_property_readonly(
          "vlrs", [](const LasLayout& l) { return recordsOf(l.vlrs); },
          "[(user_id, record_id, description, data bytes)] in file order")
      .def_property_readonly("evlrs", [](const LasLayout& l) { return recordsOf(l.evlrs); })
      .def_property_readonly(
          "extra_bytes",
          [](const LasLayout& l) {
            py::list out;
            for (const LasExtraBytesDimension& d : l.extra_bytes)
              out.append(py::make_tuple(d.field, bytesOf(d.descriptor)));
            return out;
          },
          "[(field, 192-byte descriptor)] of the Extra Bytes VLR, in record order")
      .def_readonly("undocumented_bytes", &LasLayout::undocumented_bytes)
      .def("__repr__", [](const LasLayout& l) {
        return "LasLayout(version=" + std::to_string(l.version_major) + "." +
               std::to_string(l.version_minor) +
               ", point_format=" + std::to_string(l.point_format) +
               ", points=" + std::to_string(l.point_count) +
               ", vlrs=" + std::to_string(l.vlrs.size()) + ")";
      });

  m.def("_laz_compressible", &lazCompressible, py::arg("point_format"),
        "Whether LAZ holds records of this point format (0-3 and 6-8).");

  m.def("_las_header", &lasHeader, py::arg("path"),
        "A LAS file's header and VLRs as the library reads them (no point is read): "
        "version, point_format, record_length, points, scale, offset, bounds (min x y z, max x y "
        "z), data_offset, vlrs [(user_id bytes, record_id, data bytes)], compressed (LAZ: the "
        "header of the LAS file it stands for).");

  m.def(
      "read",
      [](const std::string& path) {
        MeshFile file = [&] {
          py::gil_scoped_release release;
          return readMeshFile(path);
        }();
        return meshFileTuple(std::move(file));
      },
      py::arg("path"),
      "(points, faces, fields, viewpoint, orientation, organized_shape, precision, las) of a "
      "file; las: a LAS file's LasLayout, else None.");

  m.def(
      "copc_info",
      [](const std::string& path) {
        const CopcInfo info = [&] {
          py::gil_scoped_release release;
          return readCopcInfo(path);
        }();
        py::list nodes;
        for (const CopcNode& n : info.nodes)
          nodes.append(
              py::make_tuple(n.key.depth, n.key.x, n.key.y, n.key.z, n.offset, n.bytes, n.points));
        py::dict d;
        d["center"] = py::make_tuple(info.center.x(), info.center.y(), info.center.z());
        d["halfsize"] = info.halfsize;
        d["spacing"] = info.spacing;
        d["gpstime"] = py::make_tuple(info.gpstime_min, info.gpstime_max);
        d["points"] = info.point_count;
        d["hierarchy_pages"] = info.hierarchy_pages;
        d["nodes"] = nodes;
        return d;
      },
      py::arg("path"),
      "A COPC file's octree: center, halfsize, spacing, gpstime, points, hierarchy_pages, nodes "
      "[(depth, x, y, z, offset, bytes, points)].");

  m.def(
      "read_copc",
      [](const std::string& path, std::optional<std::vector<std::vector<int>>> keys,
         std::optional<std::vector<double>> bounds, int max_depth) {
        CopcPoints part = [&] {
          py::gil_scoped_release release;
          if (keys) {
            std::vector<CopcKey> chosen;
            for (const auto& k : *keys) {
              if (k.size() != 4) throw pcl::BadArgumentException("a node is (depth, x, y, z)");
              chosen.push_back({k[0], k[1], k[2], k[3]});
            }
            return readCopcNodes(path, chosen);
          }
          const std::vector<double>& b = *bounds;
          return readCopcBox(path,
                             Eigen::AlignedBox3d(Eigen::Vector3d(b[0], b[1], b[2]),
                                                 Eigen::Vector3d(b[3], b[4], b[5])),
                             max_depth);
        }();
        return py::make_tuple(meshFileTuple(std::move(part.file)), part.bytes_read);
      },
      py::arg("path"), py::arg("nodes"), py::arg("bounds"), py::arg("max_depth"),
      "(read's tuple, bytes read) of a COPC file's chosen nodes (depth, x, y, z), or of the "
      "points within bounds (min x y z, max x y z) from the nodes down to max_depth (-1: all).");

  m.def(
      "write",
      [](const std::string& path, const py::array& points, const py::object& faces,
         const std::optional<py::dict>& fields, std::optional<std::vector<double>> viewpoint,
         std::optional<std::string> precision, const std::string& encoding,
         std::optional<std::pair<int, int>> organized_shape, std::shared_ptr<LasLayout> las) {
        const Eigen::Matrix3Xd positions = positionsOf(points, "points");
        const int n = static_cast<int>(positions.cols());
        pcl::PolygonMesh mesh;
        mesh.cloud.width = static_cast<std::uint32_t>(n);
        mesh.cloud.height = 1;
        if (organized_shape) {
          const auto [h, w] = *organized_shape;
          if (h < 1 || w < 1 || static_cast<long long>(h) * w != n)
            throw py::value_error("organized_shape (h, w) must have h * w = the point count");
          mesh.cloud.height = static_cast<std::uint32_t>(h);
          mesh.cloud.width = static_cast<std::uint32_t>(w);
        }
        mesh.cloud.is_dense = positions.allFinite();
        setVertexCoordinates(mesh.cloud, positions,
                             precisionOf(precision, points.dtype(), positions));
        const std::string extension = fileExtension(path);
        // LAS: every field in its own type, (n, c) as one field of c values (Extra Bytes arrays).
        std::vector<TypedField> typed;
        if (fields) {
          for (const auto& [key, value] : *fields) {
            const std::string name = py::str(key);
            const py::array array = py::array::ensure(value);
            if (!array || array.ndim() < 1 || array.shape(0) != n)
              throw py::value_error("field '" + name + "' must have one row per point");
            if ((extension == "las" || extension == "laz") && name != "rgb") {
              if (array.ndim() > 2)
                throw py::value_error("field '" + name + "' has more than 2 dimensions");
              const std::uint8_t datatype = pclTypeOf(array.dtype());
              if (datatype == 0) throw py::value_error("field '" + name + "' must hold numbers");
              const auto columns =
                  static_cast<std::uint32_t>(array.ndim() == 2 ? array.shape(1) : 1);
              py::array values = py::array::ensure(
                  array.dtype().kind() == 'b' ? array.attr("astype")("uint8") : py::object(array),
                  py::array::c_style);
              if (name == "normals") {
                if (columns != 3) throw py::value_error("field 'normals' must have shape (n, 3)");
                // normal_x normal_y normal_z: the writer's NormalX NormalY NormalZ
                for (int c = 0; c < 3; ++c) {
                  typed.push_back(
                      {std::string("normal_") + "xyz"[c], datatype, 1,
                       py::array::ensure(values[py::make_tuple(py::ellipsis(), c)].attr("copy")(),
                                         py::array::c_style)});
                }
                continue;
              }
              typed.push_back({name, datatype, columns, values});
              continue;
            }
            if (name == "rgb") {
              if (array.ndim() != 2 || array.shape(1) != 3 || array.dtype().kind() != 'u' ||
                  array.dtype().itemsize() != 1)
                throw py::value_error("field 'rgb' must be uint8 of shape (n, 3)");
              const auto rgb =
                  py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(
                      array);
              VertexColors colors(3, n);
              std::memcpy(colors.data(), rgb.data(), static_cast<std::size_t>(3) * n);
              setVertexColors(mesh.cloud, colors,
                              extension == "pcd" ? ColorLayout::PackedRGB : ColorLayout::Channels);
              continue;
            }
            const char kind = array.dtype().kind();
            if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b')
              throw py::value_error("field '" + name + "' must hold numbers");
            const auto values =
                py::array_t<double, py::array::f_style | py::array::forcecast>::ensure(array);
            const Eigen::Index columns = array.ndim() == 2 ? array.shape(1) : 1;
            if (array.ndim() > 2)
              throw py::value_error("field '" + name + "' has more than 2 dimensions");
            const Eigen::Map<const Eigen::MatrixXd> matrix(values.data(), n, columns);
            std::vector<std::string> names;
            if (name == "normals") {
              if (columns != 3) throw py::value_error("field 'normals' must have shape (n, 3)");
              names = extension == "pcd"
                          ? std::vector<std::string>{"normal_x", "normal_y", "normal_z"}
                          : std::vector<std::string>{"nx", "ny", "nz"};
            } else if (columns == 1) {
              names = {name};
            } else {
              for (Eigen::Index c = 0; c < columns; ++c)
                names.push_back(name + "_" + std::to_string(c));
            }
            setVertexFields(mesh.cloud, names, matrix.transpose(),
                            precisionOf(precision, array.dtype(), matrix));
          }
        }
        if (!typed.empty() && mesh.cloud.height != 1)
          throw py::value_error("a .las file holds no organized cloud");
        appendTypedFields(mesh.cloud, typed);
        MeshWriteOptions options;
        if (py::isinstance<py::array>(faces))
          options.faces = faceRowsOf(n, faces.cast<py::array>());
        else if (!faces.is_none())
          mesh.polygons = polygonsOf(n, faces);
        options.las = las;
        options.ply_encoding = choice("encoding", encoding, {"binary", "ascii"}) == "ascii"
                                   ? PlyEncoding::Ascii
                                   : PlyEncoding::Binary;
        if (viewpoint) {
          if (viewpoint->size() != 3) throw py::value_error("viewpoint must be three numbers");
          options.sensor_pose.origin = Eigen::Vector3d(viewpoint->data());
        }
        py::gil_scoped_release release;
        saveMesh(path, mesh, options);
      },
      py::arg("path"), py::arg("points"), py::arg("faces") = py::none(),
      py::arg("fields") = py::none(), py::arg("viewpoint") = py::none(),
      py::arg("precision") = py::none(), py::arg("encoding") = "binary",
      py::arg("organized_shape") = py::none(), py::arg("las") = py::none(),
      "saveMesh of points, faces and fields; las: the LasLayout a .las output keeps.");
}

}  // namespace python
}  // namespace pcl_ddg
