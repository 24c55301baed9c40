#include "pcl_ddg/features/ring_surface_variation.h"

#include <limits>

#include "pcl_ddg/features/plane_fit.h"

namespace pcl_ddg {

Eigen::VectorXd ringSurfaceVariation(const MeshTopology& topology,
                                     const Eigen::Matrix3Xd& positions) {
  const int n = topology.numVertices();
  Eigen::VectorXd variation(n);
#pragma omp parallel
  {
    Eigen::Matrix3Xd ring;  // per thread, grown to the largest ring it meets
#pragma omp for schedule(static)
    for (int v = 0; v < n; ++v) {
      const IndexSpan neighbours = topology.neighbours(v);
      const int count = neighbours.size() + 1;
      if (ring.cols() < count) ring.resize(3, 2 * count);
      // Relative to the vertex: the covariance never sees the scan's distance from the origin.
      ring.col(0).setZero();
      for (int i = 0; i < neighbours.size(); ++i)
        ring.col(i + 1) = positions.col(neighbours[i]) - positions.col(v);
      const PlaneFit fit = fitPlane(ring, count);
      variation[v] = fit.valid ? fit.surface_variation : std::numeric_limits<double>::quiet_NaN();
    }
  }
  return variation;
}

}  // namespace pcl_ddg
