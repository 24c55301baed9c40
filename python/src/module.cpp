// _pcl_ddg: the compiled half of the pcl_ddg Python package (python/pcl_ddg wraps it with
// validation, named tuples and docstrings). Exceptions keep the library's message: an
// InvalidMeshException becomes pcl_ddg.InvalidMeshError (a ValueError), a file error OSError, a bad
// parameter ValueError, a failed computation RuntimeError.
#include <pcl/console/print.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "binding_common.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/surface/mesh_smoothing.h"
#include "pcl_ddg/version.h"

namespace pcl_ddg {
namespace python {

namespace {

bool isRealDtype(const py::dtype& dtype) {
  const char kind = dtype.kind();
  return kind == 'f' || kind == 'i' || kind == 'u';
}

// Element (row, column) of a 2-D real array of any dtype and strides.
template <typename T>
void copyRows(const py::array& array, Eigen::Matrix3Xd& out) {
  const auto* base = static_cast<const char*>(array.data());
  const py::ssize_t s0 = array.strides(0), s1 = array.strides(1);
  for (Eigen::Index i = 0; i < out.cols(); ++i) {
    for (int d = 0; d < 3; ++d)
      out(d, i) = static_cast<double>(*reinterpret_cast<const T*>(base + i * s0 + d * s1));
  }
}

template <typename T>
bool dispatchRows(const py::array& array, Eigen::Matrix3Xd& out) {
  if (!py::dtype::of<T>().is(array.dtype()) &&
      !(py::dtype::of<T>().kind() == array.dtype().kind() &&
        py::dtype::of<T>().itemsize() == array.dtype().itemsize()))
    return false;
  copyRows<T>(array, out);
  return true;
}

bool isFloat64CContiguous(const py::array& array) {
  return array.dtype().kind() == 'f' && array.dtype().itemsize() == 8 &&
         (array.flags() & py::array::c_style) != 0 && array.dtype().byteorder() != '>';
}

}  // namespace

int rowCount(const py::array& array, const char* name) {
  if (array.ndim() != 2 || array.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d)
      shape += (d ? ", " : "") + std::to_string(array.shape(d));
    throw py::value_error(std::string(name) + " must have shape (n, 3), not " + shape +
                          (array.ndim() == 1 ? ",)" : ")"));
  }
  if (!isRealDtype(array.dtype()) || array.dtype().kind() == 'b')
    throw py::value_error(std::string(name) + " must hold real numbers, not " +
                          std::string(py::str(array.dtype())));
  if (array.shape(0) > std::numeric_limits<int>::max())
    throw py::value_error(std::string(name) + " has more rows than the library indexes");
  return static_cast<int>(array.shape(0));
}

Eigen::Matrix3Xd positionsOf(const py::array& array, const char* name) {
  const int n = rowCount(array, name);
  Eigen::Matrix3Xd out(3, n);
  if (n == 0) return out;
  if (isFloat64CContiguous(array)) {
    // The library takes an owning Eigen::Matrix3Xd: one memcpy, without the GIL.
    py::gil_scoped_release release;
    std::memcpy(out.data(), array.data(), sizeof(double) * 3 * static_cast<std::size_t>(n));
    return out;
  }
  if (array.dtype().byteorder() == '>') {
    // Rare (big-endian files mapped by NumPy): converted by NumPy, then read in place.
    return positionsOf(py::array_t<double, py::array::c_style | py::array::forcecast>(array), name);
  }
  if (dispatchRows<double>(array, out) || dispatchRows<float>(array, out) ||
      dispatchRows<std::int64_t>(array, out) || dispatchRows<std::int32_t>(array, out) ||
      dispatchRows<std::uint32_t>(array, out) || dispatchRows<std::uint64_t>(array, out) ||
      dispatchRows<std::int16_t>(array, out) || dispatchRows<std::uint16_t>(array, out) ||
      dispatchRows<std::int8_t>(array, out) || dispatchRows<std::uint8_t>(array, out))
    return out;
  // long double, float16: NumPy converts.
  return positionsOf(py::array_t<double, py::array::c_style | py::array::forcecast>(array), name);
}

PositionsView::PositionsView(const py::array& array, const char* name) {
  if (isFloat64CContiguous(array)) {
    cols_ = rowCount(array, name);
    in_place_ = static_cast<const double*>(array.data());
  } else {
    converted_ = positionsOf(array, name);
    cols_ = converted_.cols();
  }
  lastPositionsAddress() = reinterpret_cast<std::uintptr_t>(map().data());
}

std::uintptr_t& lastPositionsAddress() {
  thread_local std::uintptr_t address = 0;
  return address;
}

int checkedIndex(long long index, int num_vertices, std::size_t face) {
  if (index < 0 || index >= num_vertices) {
    throw py::value_error("face " + std::to_string(face) + " names vertex " +
                          std::to_string(index) + ", outside 0.." +
                          std::to_string(num_vertices - 1) + " (" + std::to_string(num_vertices) +
                          " vertices)");
  }
  return static_cast<int>(index);
}

namespace {

// Policy Drop: an out-of-range index (negative ones too) as one the library drops.
int droppableIndex(long long index, int num_vertices) {
  return index < 0 || index >= num_vertices ? num_vertices : static_cast<int>(index);
}

}  // namespace

namespace {

// Builds the topology with the GIL released, its time counted as the library's.
template <typename Polygons>
MeshTopology buildTopology(int num_vertices, const Polygons& polygons,
                           OutOfRangeFacePolicy policy) {
  const auto start = std::chrono::steady_clock::now();
  py::gil_scoped_release release;
  MeshTopology topology(num_vertices, polygons, policy);
  pendingComputeSeconds() =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return topology;
}

}  // namespace

namespace {

void checkFaceArray(const py::array& f) {
  const char kind = f.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::value_error("F must hold integers (int32 or int64), not " +
                          std::string(py::str(f.dtype())));
  if (f.ndim() != 2 || (f.shape(1) < 3 && f.shape(0) > 0))
    throw py::value_error("F must have shape (m, 3) (or (m, k) polygons, or a list of them)");
}

}  // namespace

py::array_t<long long, py::array::c_style> faceRows(const py::array& faces) {
  checkFaceArray(faces);
  return py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(faces);
}

MeshTopology topologyOf(int num_vertices, const py::object& faces, OutOfRangeFacePolicy policy) {
  const bool check = policy == OutOfRangeFacePolicy::Throw;
  if (py::isinstance<py::array>(faces)) {
    const py::array f = faces.cast<py::array>();
    checkFaceArray(f);
    const auto rows = static_cast<std::size_t>(f.shape(0));
    const auto corners = static_cast<std::size_t>(f.ndim() == 2 ? f.shape(1) : 0);
    if (corners == 3 && f.dtype().kind() == 'i' && f.dtype().itemsize() == 4 &&
        f.dtype().byteorder() != '>' && (f.flags() & py::array::c_style) != 0) {
      // int32 (m, 3) C-contiguous: the triangles' own layout, read in place and checked without
      // the GIL; copied only to drop out-of-range corners.
      const Eigen::Map<const Eigen::Matrix3Xi> in_place(static_cast<const int*>(f.data()), 3,
                                                        static_cast<Eigen::Index>(rows));
      std::int64_t bad = -1;
      {
        py::gil_scoped_release release;
        const int* data = in_place.data();
        for (std::size_t i = 0; i < 3 * rows && bad < 0; i += 3 * 4096) {
          // Blocks: a vectorisable range check, the offender searched only in a failing block.
          const std::size_t end = std::min(3 * rows, i + 3 * 4096);
          bool ok = true;
          for (std::size_t j = i; j < end; ++j) ok &= data[j] >= 0 && data[j] < num_vertices;
          if (!ok) {
            for (std::size_t j = i; j < end && bad < 0; ++j)
              if (data[j] < 0 || data[j] >= num_vertices) bad = static_cast<std::int64_t>(j);
          }
        }
      }
      if (bad < 0) return buildTopology(num_vertices, in_place, policy);
      if (check)
        checkedIndex(in_place.data()[bad], num_vertices, static_cast<std::size_t>(bad / 3));
      Eigen::Matrix3Xi triangles = in_place;
      for (Eigen::Index j = 0; j < triangles.size(); ++j)
        triangles.data()[j] = droppableIndex(triangles.data()[j], num_vertices);
      return buildTopology(num_vertices, triangles, policy);
    }
    const auto indices = py::array_t<long long, py::array::c_style | py::array::forcecast>(f);
    const long long* data = indices.data();
    if (corners == 3) {
      Eigen::Matrix3Xi triangles(3, static_cast<Eigen::Index>(rows));
      for (std::size_t t = 0; t < rows; ++t) {
        for (int c = 0; c < 3; ++c) {
          const long long index = data[3 * t + c];
          triangles(c, static_cast<Eigen::Index>(t)) =
              check ? checkedIndex(index, num_vertices, t) : droppableIndex(index, num_vertices);
        }
      }
      return buildTopology(num_vertices, triangles, policy);
    }
    std::vector<pcl::Vertices> polygons(rows);
    for (std::size_t t = 0; t < rows; ++t) {
      polygons[t].vertices.resize(corners);
      for (std::size_t c = 0; c < corners; ++c) {
        const long long index = data[corners * t + c];
        polygons[t].vertices[c] =
            check ? static_cast<std::uint32_t>(checkedIndex(index, num_vertices, t))
                  : static_cast<std::uint32_t>(droppableIndex(index, num_vertices));
      }
    }
    return buildTopology(num_vertices, polygons, policy);
  }
  if (!py::isinstance<py::sequence>(faces) || py::isinstance<py::str>(faces))
    throw py::value_error("F must be an (m, 3) integer array or a sequence of polygons");
  const auto sequence = faces.cast<py::sequence>();
  std::vector<pcl::Vertices> polygons(sequence.size());
  for (std::size_t t = 0; t < polygons.size(); ++t) {
    const py::object polygon = sequence[t];
    const py::array p = py::array::ensure(polygon);
    if (!p || p.ndim() != 1 || (p.size() > 0 && p.dtype().kind() != 'i' && p.dtype().kind() != 'u'))
      throw py::value_error("polygon " + std::to_string(t) + " of F is not a sequence of integers");
    const auto indices = py::array_t<long long, py::array::c_style | py::array::forcecast>(p);
    polygons[t].vertices.resize(static_cast<std::size_t>(p.size()));
    for (py::ssize_t c = 0; c < p.size(); ++c) {
      const long long index = indices.data()[c];
      polygons[t].vertices[c] =
          check ? static_cast<std::uint32_t>(checkedIndex(index, num_vertices, t))
                : static_cast<std::uint32_t>(droppableIndex(index, num_vertices));
    }
  }
  return buildTopology(num_vertices, polygons, policy);
}

std::string choice(const std::string& option, const std::string& value,
                   std::initializer_list<const char*> choices) {
  std::string names;
  for (const char* c : choices) {
    if (value == c) return value;
    names += (names.empty() ? "" : ", ") + std::string("'") + c + "'";
  }
  throw py::value_error(option + " must be one of " + names + ", not '" + value + "'");
}

py::array_t<double> rowsArray(Eigen::Matrix3Xd&& matrix) {
  auto* owned = new Eigen::Matrix3Xd(std::move(matrix));
  py::capsule owner(owned, [](void* p) { delete static_cast<Eigen::Matrix3Xd*>(p); });
  return py::array_t<double>({static_cast<py::ssize_t>(owned->cols()), py::ssize_t{3}},
                             {py::ssize_t{3 * sizeof(double)}, py::ssize_t{sizeof(double)}},
                             owned->data(), owner);
}

py::array_t<double> vectorArray(Eigen::VectorXd&& values) {
  auto* owned = new Eigen::VectorXd(std::move(values));
  py::capsule owner(owned, [](void* p) { delete static_cast<Eigen::VectorXd*>(p); });
  return py::array_t<double>({static_cast<py::ssize_t>(owned->size())}, owned->data(), owner);
}

py::array_t<bool> maskArray(const std::vector<std::uint8_t>& valid) {
  py::array_t<bool> mask(static_cast<py::ssize_t>(valid.size()));
  bool* out = mask.mutable_data();
  for (std::size_t i = 0; i < valid.size(); ++i) out[i] = valid[i] != 0;
  return mask;
}

double& lastComputeSeconds() {
  thread_local double seconds = 0.0;
  return seconds;
}

double& pendingComputeSeconds() {
  thread_local double seconds = 0.0;
  return seconds;
}

bool pythonSignalRaised() {
  py::gil_scoped_acquire acquire;
  return PyErr_CheckSignals() != 0;
}

void setError(PyObject* type, const std::exception& e) {
  // A message may quote a file's bytes: what is not UTF-8 is escaped (\\xff), never lost.
  const std::string text = pcl_ddg::errorDescription(e);
  PyObject* message =
      PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "backslashreplace");
  if (message == nullptr) return;  // MemoryError is set
  PyErr_SetObject(type, message);
  Py_DECREF(message);
}

}  // namespace python
}  // namespace pcl_ddg

PYBIND11_MODULE(_pcl_ddg, m) {
  namespace py = pybind11;
  using namespace pcl_ddg::python;
  m.doc() = "pcl_ddg's compiled functions; use the pcl_ddg package, which validates and documents.";
  m.attr("__version__") = PCL_DDG_VERSION_STRING;
  // The estimators' per-call warnings are counted in the results instead (as the tools do).
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);

  static py::exception<pcl_ddg::InvalidMeshException> invalid_mesh(m, "InvalidMeshError",
                                                                   PyExc_ValueError);
  static py::exception<pcl_ddg::SurfaceCollapseException> collapse(m, "SurfaceCollapseError",
                                                                   PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const pcl_ddg::InvalidMeshException& e) {
      setError(invalid_mesh.ptr(), e);
    } catch (const pcl_ddg::SurfaceCollapseException& e) {
      setError(collapse.ptr(), e);
    } catch (const pcl_ddg::InterruptedException&) {
      // Python's handler raised KeyboardInterrupt when the library asked (pythonSignalRaised).
      if (PyErr_Occurred() == nullptr) PyErr_SetNone(PyExc_KeyboardInterrupt);
    } catch (const pcl::IOException& e) {
      setError(PyExc_OSError, e);
    } catch (const pcl::BadArgumentException& e) {
      setError(PyExc_ValueError, e);
    } catch (const pcl::PCLException& e) {
      setError(PyExc_RuntimeError, e);
    } catch (const py::builtin_exception&) {
      throw;  // pybind11's own (py::value_error, ...): its translator sets them
    } catch (const std::bad_alloc&) {
      throw;  // MemoryError, by pybind11's translator
    } catch (const std::exception& e) {
      setError(PyExc_RuntimeError, e);
    }
  });

  m.def(
      "_last_compute_seconds", [] { return lastComputeSeconds(); },
      "Seconds the last call of this thread spent in the library (GIL released).");
  m.def(
      "_last_positions_address", [] { return lastPositionsAddress(); },
      "The address this thread's last mesh call read V from (V's own buffer when read in place).");
  bindMeshes(m);
  bindClouds(m);
  bindIO(m);
  bindDistributed(m);
}
