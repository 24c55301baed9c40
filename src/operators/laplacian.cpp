#include "pcl_ddg/operators/laplacian.h"

#include <algorithm>

#include "detail/triangle_geometry.h"

namespace pcl_ddg {
namespace {

template <int Storage>
using Sparse = Eigen::SparseMatrix<double, Storage>;

// The pattern of L (graph neighbours plus the diagonal), compressed, values zero. The pattern is
// symmetric, so the outer vector of v (its column, or its row) holds exactly the neighbours of v.
template <int Storage>
Sparse<Storage> graphPattern(const MeshTopology& topology) {
  const int n = topology.numVertices();
  Sparse<Storage> matrix(n, n);
  std::int64_t nnz = n;
  for (int v = 0; v < n; ++v) nnz += topology.neighbours(v).size();
  matrix.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  int* outer = matrix.outerIndexPtr();
  int* inner = matrix.innerIndexPtr();
  outer[0] = 0;
  for (int v = 0; v < n; ++v) outer[v + 1] = outer[v] + topology.neighbours(v).size() + 1;
#pragma omp parallel for schedule(static)
  for (int v = 0; v < n; ++v) {
    const IndexSpan row = topology.neighbours(v);
    int* out = inner + outer[v];
    const int* split = std::lower_bound(row.begin(), row.end(), v);
    out = std::copy(row.begin(), split, out);
    *out++ = v;
    std::copy(split, row.end(), out);
  }
  std::fill(matrix.valuePtr(), matrix.valuePtr() + nnz, 0.0);
  return matrix;
}

// Position of vertex w in the outer vector of v.
template <int Storage>
Eigen::Index slot(const Sparse<Storage>& m, int v, int w) {
  const int* first = m.innerIndexPtr() + m.outerIndexPtr()[v];
  const int* last = m.innerIndexPtr() + m.outerIndexPtr()[v + 1];
  return std::lower_bound(first, last, w) - m.innerIndexPtr();
}

// Diagonal = minus the sum of the off-diagonal entries of each outer vector.
template <int Storage>
void setDiagonalFromSums(Sparse<Storage>& m) {
#pragma omp parallel for schedule(static)
  for (Eigen::Index v = 0; v < m.outerSize(); ++v) {
    double sum = 0.0;
    Eigen::Index diagonal = -1;
    for (Eigen::Index k = m.outerIndexPtr()[v]; k < m.outerIndexPtr()[v + 1]; ++k) {
      if (m.innerIndexPtr()[k] == v) {
        diagonal = k;
      } else {
        sum += m.valuePtr()[k];
      }
    }
    m.valuePtr()[diagonal] = -sum;
  }
}

template <int Storage>
Sparse<Storage> uniform(const MeshTopology& topology) {
  Sparse<Storage> l = graphPattern<Storage>(topology);
  std::fill(l.valuePtr(), l.valuePtr() + l.nonZeros(), 1.0);
  setDiagonalFromSums(l);
  return l;
}

template <int Storage>
Sparse<Storage> cotangent(const MeshTopology& topology, const PositionsRef& positions) {
  detail::requireMatchingPositions(topology, positions);
  Sparse<Storage> l = graphPattern<Storage>(topology);
  const Eigen::Matrix3Xi& tris = topology.triangles();
  // Gather: vertex v sums, over its triangles, half the cotangent opposite each edge at v. Each
  // triangle is seen from its own corner 0 whichever vertex gathers, and the triangles of a vertex
  // come in ascending order: both ends of an edge add the same terms in the same order, so L equals
  // its transpose bit for bit and its compressed columns are its compressed rows.
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    for (const int t : topology.incidentTriangles(v)) {
      const detail::CornerView c = detail::viewFromCorner(positions, tris, t, 0);
      if (c.degenerate) continue;
      const int k = detail::cornerOf(tris, t, v);
      const int a = tris((k + 1) % 3, t), b = tris((k + 2) % 3, t);
      l.valuePtr()[slot(l, v, a)] += 0.5 * c.cotangent((k + 2) % 3);  // edge va, opposite b
      l.valuePtr()[slot(l, v, b)] += 0.5 * c.cotangent((k + 1) % 3);  // edge vb, opposite a
    }
  }
  setDiagonalFromSums(l);
  return l;
}

// Row i divided by mass_i: the row of an entry is its inner index in compressed columns, its
// outer index in compressed rows.
template <int Storage>
void divideRows(Sparse<Storage>& matrix, const Eigen::VectorXd& mass) {
  double* values = matrix.valuePtr();
  const int* inner = matrix.innerIndexPtr();
  const int* outer = matrix.outerIndexPtr();
#pragma omp parallel for schedule(static)
  for (Eigen::Index o = 0; o < matrix.outerSize(); ++o) {
    for (Eigen::Index k = outer[o]; k < outer[o + 1]; ++k) {
      const double m = mass[Storage == Eigen::RowMajor ? o : inner[k]];
      values[k] = m > 0.0 ? values[k] / m : 0.0;
    }
  }
}

}  // namespace

Eigen::SparseMatrix<double> cotangentLaplacian(const MeshTopology& topology,
                                               const PositionsRef& positions) {
  return cotangent<Eigen::ColMajor>(topology, positions);
}

template <int Storage>
Eigen::SparseMatrix<double, Storage> laplacian(const MeshTopology& topology,
                                               const PositionsRef& positions,
                                               LaplacianWeights weights, LaplacianForm form,
                                               MassType mass) {
  detail::requireMatchingPositions(topology, positions);
  Sparse<Storage> l = weights == LaplacianWeights::Cotangent
                          ? cotangent<Storage>(topology, positions)
                          : uniform<Storage>(topology);
  if (form == LaplacianForm::Averaged) divideRows(l, lumpedMass(topology, positions, mass));
  return l;
}

template Eigen::SparseMatrix<double, Eigen::ColMajor> laplacian<Eigen::ColMajor>(
    const MeshTopology&, const PositionsRef&, LaplacianWeights, LaplacianForm, MassType);
template Eigen::SparseMatrix<double, Eigen::RowMajor> laplacian<Eigen::RowMajor>(
    const MeshTopology&, const PositionsRef&, LaplacianWeights, LaplacianForm, MassType);

}  // namespace pcl_ddg
