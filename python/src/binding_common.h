#pragma once
// What every part of the _pcl_ddg module shares: reading NumPy arrays (float64 C-contiguous in
// place, anything else converted once), handing Eigen results to NumPy without a copy, option
// strings, and the timing of the library call (bench/bench_python.py measures the binding's
// overhead with it).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "pcl_ddg/interruption.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {
namespace python {

namespace py = pybind11;

/** An (n, 3) array's rows as a 3 x n matrix in double (one pass over any dtype and strides: a
 *  memcpy for float64 C-contiguous input). Throws ValueError for another shape or a non-real
 *  dtype. */
Eigen::Matrix3Xd positionsOf(const py::array& array, const char* name);

/** An (n, 3) array's rows as the library's 3 x n positions: float64 C-contiguous arrays in place
 *  (their rows are the library's columns, the same bytes), any other array converted once. The
 *  array must outlive the view (a function argument does), and nothing may write to it while the
 *  library reads it with the GIL released (as with any NumPy buffer shared between threads). */
class PositionsView {
 public:
  PositionsView(const py::array& array, const char* name);
  Eigen::Map<const Eigen::Matrix3Xd> map() const {
    return in_place_ ? Eigen::Map<const Eigen::Matrix3Xd>(in_place_, 3, cols_)
                     : Eigen::Map<const Eigen::Matrix3Xd>(converted_.data(), 3, cols_);
  }
  Eigen::Index cols() const { return cols_; }

 private:
  const double* in_place_ = nullptr;  ///< the array's buffer; null when converted
  Eigen::Matrix3Xd converted_;
  Eigen::Index cols_ = 0;
};

/** The address the last PositionsView of this thread read positions from: the array's own buffer
 *  when it was read in place, the converted copy's otherwise (the tests' evidence of zero copy). */
std::uintptr_t& lastPositionsAddress();

/** A mesh's topology from F: an (m, 3) integer array or a sequence of polygons. Indices are
 *  checked against num_vertices (ValueError naming the face). */
/** A face index as an int, or ValueError naming the face when it is outside 0..num_vertices-1. */
int checkedIndex(long long index, int num_vertices, std::size_t face);

/** An (m, k) integer face array (k >= 3; else ValueError) as C-contiguous int64 rows. */
py::array_t<long long, py::array::c_style> faceRows(const py::array& faces);

MeshTopology topologyOf(int num_vertices, const py::object& faces,
                        OutOfRangeFacePolicy policy = OutOfRangeFacePolicy::Throw);

/** The number of rows of an (n, 3) array, checked. */
int rowCount(const py::array& array, const char* name);

/** value, if it is one of choices; else ValueError naming them. */
std::string choice(const std::string& option, const std::string& value,
                   std::initializer_list<const char*> choices);

/** A 3 x n matrix as an (n, 3) float64 array that owns it (no copy). */
py::array_t<double> rowsArray(Eigen::Matrix3Xd&& matrix);

/** A vector as an (n,) array that owns it (no copy). */
template <typename T>
py::array_t<T> vectorArray(std::vector<T>&& values) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>({static_cast<py::ssize_t>(owned->size())}, owned->data(), owner);
}

py::array_t<double> vectorArray(Eigen::VectorXd&& values);

/** 0/1 bytes as a bool array. */
py::array_t<bool> maskArray(const std::vector<std::uint8_t>& valid);

/** Seconds the last library call of this thread took, its GIL released, the topology built for it
 *  included: the C++ side of the binding's overhead. */
double& lastComputeSeconds();
/** Library time spent before the call (building the topology), added to it by compute(). */
double& pendingComputeSeconds();

/** True when Python's signal handlers raised (Ctrl-C: KeyboardInterrupt is then set). Takes
 *  the GIL; only the main thread runs handlers, elsewhere it is false. */
bool pythonSignalRaised();

/** Runs body with the GIL released, interruptible by Ctrl-C (the library's long loops poll
 *  pythonSignalRaised about every 0.1 s: interruption.h), and records how long it took. */
template <typename Body>
auto compute(Body&& body) {
  const auto start = std::chrono::steady_clock::now();
  struct Record {
    std::chrono::steady_clock::time_point start;
    ~Record() {
      lastComputeSeconds() =
          pendingComputeSeconds() +
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      pendingComputeSeconds() = 0.0;
    }
  } record{start};
  py::gil_scoped_release release;
  const InterruptionScope interruptible(pythonSignalRaised);
  return body();
}

/** Sets a Python exception of type with e's description (errorDescription), its bytes that are
 *  not UTF-8 escaped. */
void setError(PyObject* type, const std::exception& e);

void bindMeshes(py::module_& m);
void bindClouds(py::module_& m);
void bindIO(py::module_& m);
void bindDistributed(py::module_& m);

}  // namespace python
}  // namespace pcl_ddg
