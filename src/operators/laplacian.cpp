#include "pcl_ddg/operators/laplacian.h"

#include <algorithm>

#include "triangle_geometry.h"

namespace pcl_ddg {
namespace {

// The pattern of L (graph neighbours plus the diagonal), compressed, values zero. The matrix is
// symmetric in pattern, so column v holds exactly the row of v.
Eigen::SparseMatrix<double> graphPattern(const MeshTopology& topology) {
  const int n = topology.numVertices();
  Eigen::SparseMatrix<double> matrix(n, n);
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

// Position of vertex w in column v of the pattern.
inline Eigen::Index slot(const Eigen::SparseMatrix<double>& m, int v, int w) {
  const int* first = m.innerIndexPtr() + m.outerIndexPtr()[v];
  const int* last = m.innerIndexPtr() + m.outerIndexPtr()[v + 1];
  return std::lower_bound(first, last, w) - m.innerIndexPtr();
}

// Diagonal = minus the sum of the off-diagonal entries of each column.
void setDiagonalFromRowSums(Eigen::SparseMatrix<double>& m) {
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

}  // namespace

Eigen::SparseMatrix<double> uniformLaplacian(const MeshTopology& topology) {
  Eigen::SparseMatrix<double> l = graphPattern(topology);
  std::fill(l.valuePtr(), l.valuePtr() + l.nonZeros(), 1.0);
  setDiagonalFromRowSums(l);
  return l;
}

Eigen::SparseMatrix<double> cotangentLaplacian(const MeshTopology& topology,
                                               const Eigen::Matrix3Xd& positions) {
  detail::requireMatchingPositions(topology, positions);
  Eigen::SparseMatrix<double> l = graphPattern(topology);
  const Eigen::Matrix3Xi& tris = topology.triangles();
  // Gather: column v sums, over its triangles, half the cotangent opposite each edge at v.
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    detail::forEachCornerOf(topology, positions, v, [&](const detail::CornerView& c, int t) {
      const int k = detail::cornerOf(tris, t, v);
      const int a = tris((k + 1) % 3, t), b = tris((k + 2) % 3, t);
      l.valuePtr()[slot(l, v, a)] += 0.5 * c.cotangent(2);  // edge va, opposite b
      l.valuePtr()[slot(l, v, b)] += 0.5 * c.cotangent(1);  // edge vb, opposite a
    });
  }
  setDiagonalFromRowSums(l);
  return l;
}

void divideRowsByMass(Eigen::SparseMatrix<double>& matrix, const Eigen::VectorXd& mass) {
  double* values = matrix.valuePtr();
  const int* rows = matrix.innerIndexPtr();
#pragma omp parallel for schedule(static)
  for (Eigen::Index k = 0; k < matrix.nonZeros(); ++k) {
    const double m = mass[rows[k]];
    values[k] = m > 0.0 ? values[k] / m : 0.0;
  }
}

Eigen::SparseMatrix<double> laplacian(const MeshTopology& topology,
                                      const Eigen::Matrix3Xd& positions, LaplacianWeights weights,
                                      LaplacianForm form, MassType mass) {
  detail::requireMatchingPositions(topology, positions);
  Eigen::SparseMatrix<double> l = weights == LaplacianWeights::Cotangent
                                      ? cotangentLaplacian(topology, positions)
                                      : uniformLaplacian(topology);
  if (form == LaplacianForm::Averaged) divideRowsByMass(l, lumpedMass(topology, positions, mass));
  return l;
}

}  // namespace pcl_ddg
