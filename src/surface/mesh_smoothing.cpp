#include "pcl_ddg/surface/mesh_smoothing.h"

#include <pcl/exceptions.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "laplacian_flow.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/local_cloud.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/surface/inner_ball.h"

namespace pcl_ddg {
namespace {

[[noreturn]] void badArgument(const std::string& what) {
  throw pcl::BadArgumentException(what);
}

[[noreturn]] void failedAt(int iteration, const std::string& what) {
  throw pcl::ComputeFailedException("smoothing iteration " + std::to_string(iteration) + ": " +
                                    what);
}

bool isClosedAndOriented(const MeshTopology& topology) {
  const TopologyCounts& counts = topology.counts();
  return counts.boundary_edges == 0 && counts.nonmanifold_edges == 0 &&
         counts.consistently_oriented && topology.numTriangles() > 0;
}

// Area-weighted centroid of the triangles: the point the shrinkage correction scales about.
Eigen::Vector3d surfaceCentroid(const MeshTopology& topology, const Eigen::Matrix3Xd& x) {
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double area = 0.0;
  const Eigen::Matrix3Xi& t = topology.triangles();
  for (Eigen::Index f = 0; f < t.cols(); ++f) {
    const Eigen::Vector3d a = x.col(t(0, f)), b = x.col(t(1, f)), c = x.col(t(2, f));
    const double triangle_area = 0.5 * (b - a).cross(c - a).norm();
    weighted += triangle_area * (a + b + c) / 3.0;
    area += triangle_area;
  }
  return area > 0.0 ? Eigen::Vector3d(weighted / area) : Eigen::Vector3d(x.rowwise().mean());
}

/** Throws SurfaceCollapseException when `current` is what is left of a collapsed surface (see
 *  the header): area, volume (closed meshes: volume_before != 0), or every vertex within h of
 *  the centroid (h = 0: not checked). */
void requireNotCollapsed(const MeshTopology& topology, const Eigen::Matrix3Xd& current,
                         double area_before, double volume_before, double h, int iteration) {
  constexpr double kCollapsed = 1e-6;
  std::string what;
  char ratio[32];
  const double area = surfaceArea(topology, current);
  if (area < kCollapsed * area_before) {
    std::snprintf(ratio, sizeof ratio, "%.3g", area / area_before);
    what = std::string("its area is ") + ratio + " of the input's";
  } else if (volume_before != 0.0 &&
             std::abs(enclosedVolume(topology, current)) < kCollapsed * std::abs(volume_before)) {
    std::snprintf(ratio, sizeof ratio, "%.3g",
                  std::abs(enclosedVolume(topology, current) / volume_before));
    what = std::string("its volume is ") + ratio + " of the input's";
  } else {
    const Eigen::Vector3d centre = surfaceCentroid(topology, current);
    if (((current.colwise() - centre).colwise().norm().array() < h).all())
      what = "every vertex is within one mean edge length of the centroid";
  }
  if (!what.empty()) {
    throw SurfaceCollapseException("smoothing iteration " + std::to_string(iteration) +
                                   ": the surface collapsed (" + what +
                                   "): the time step is too large");
  }
}

/** What divides L (see FlowAverage): the lumped mass, or the degree -diag(L). */
Eigen::VectorXd averageOf(const Eigen::SparseMatrix<double>& l, const MeshTopology& topology,
                          const PositionsRef& positions, MassType mass, FlowAverage average) {
  if (average == FlowAverage::Area) return lumpedMass(topology, positions, mass);
  return -Eigen::VectorXd(l.diagonal());
}

/** s_i = max(1, time / (limit r_i^2)), its logarithm smoothed by one implicit step of the
 *  input's operator (see the header: a slowdown that changed faster than the flow smooths would
 *  itself roughen a curved surface, and a single noise bump reads as thin). */
Eigen::ArrayXd thinPartSlowdown(const MeshTopology& topology, const Eigen::Matrix3Xd& positions,
                                const Eigen::SparseMatrix<double>& stiffness,
                                const Eigen::VectorXd& mass, const MeshSmoothingParameters& p) {
  const double time = p.time_step * p.iterations;
  // Only radii below sqrt(time / limit) slow anything down: no ball needs to start wider.
  const double widest = time > 0.0 && p.thickness_limit > 0.0
                            ? std::sqrt(time / p.thickness_limit)
                            : std::numeric_limits<double>::infinity();
  const Eigen::ArrayXd radii = innerBallRadii(topology, positions, widest).array();
  // Capped where a radius rounds to nothing: such a vertex just stays (r = inf gives 1).
  Eigen::MatrixXd log_slowdown =
      (time / (p.thickness_limit * radii.square())).max(1.0).min(1e12).log().matrix();
  if ((log_slowdown.array() == 0.0).all()) return Eigen::ArrayXd::Ones(positions.cols());
  // For at most four times what the median vertex gets (its diffusion length doubled): longer
  // would even out thin and thick parts once the time asked is far beyond the thick parts' own
  // limit.
  std::vector<double> sorted(log_slowdown.data(), log_slowdown.data() + log_slowdown.size());
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median_time = time / std::exp(sorted[sorted.size() / 2]);
  detail::LaplacianFlow heat(topology.numVertices(), {}, p.solver, p.implicit_solver);
  heat.setOperator(stiffness, mass);
  heat.implicitStep(log_slowdown, std::min(time, 4.0 * median_time));
  return log_slowdown.array().max(0.0).exp();
}

}  // namespace

double explicitStabilityLimit(const MeshTopology& topology, const PositionsRef& positions,
                              LaplacianWeights weights, MassType mass, FlowAverage average) {
  const Eigen::SparseMatrix<double> l = laplacian(topology, positions, weights);
  const Eigen::VectorXd m = averageOf(l, topology, positions, mass, average);
  double largest = 0.0;  // max_i sum_j |L_ij| / m_i (L is symmetric: columns are rows)
  for (Eigen::Index v = 0; v < l.outerSize(); ++v) {
    if (!(m[v] > 0.0)) continue;
    double row = 0.0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(l, v); it; ++it) row += std::abs(it.value());
    largest = std::max(largest, row / m[v]);
  }
  return largest > 0.0 ? 2.0 / largest : std::numeric_limits<double>::infinity();
}

std::vector<double> componentVolumes(const MeshTopology& topology, const PositionsRef& positions) {
  if (positions.cols() != topology.numVertices()) {
    throw InvalidMeshException("positions do not match the mesh");
  }
  const std::vector<int>& component = topology.vertexComponent();
  const int components =
      component.empty() ? 0 : *std::max_element(component.begin(), component.end()) + 1;
  // Tetrahedra to the mean of each component's vertices, so that scans far from the origin, and
  // components far from each other, lose no digits.
  std::vector<Eigen::Vector3d> origin(components, Eigen::Vector3d::Zero());
  std::vector<int> members(components, 0);
  for (Eigen::Index v = 0; v < positions.cols(); ++v) {
    if (component[v] < 0) continue;  // a vertex of no triangle
    origin[component[v]] += positions.col(v);
    ++members[component[v]];
  }
  for (int k = 0; k < components; ++k) origin[k] /= members[k];
  std::vector<double> six_volume(components, 0.0);
  const Eigen::Matrix3Xi& t = topology.triangles();
  for (Eigen::Index f = 0; f < t.cols(); ++f) {
    const int k = component[t(0, f)];
    const Eigen::Vector3d a = positions.col(t(0, f)) - origin[k],
                          b = positions.col(t(1, f)) - origin[k],
                          c = positions.col(t(2, f)) - origin[k];
    six_volume[k] += a.dot(b.cross(c));
  }
  for (double& v : six_volume) v /= 6.0;
  return six_volume;
}

double enclosedVolume(const MeshTopology& topology, const PositionsRef& positions) {
  const std::vector<double> volumes = componentVolumes(topology, positions);
  return std::accumulate(volumes.begin(), volumes.end(), 0.0);
}

double surfaceArea(const MeshTopology& topology, const PositionsRef& positions) {
  const Eigen::Matrix3Xi& t = topology.triangles();
  double area = 0.0;
  for (Eigen::Index f = 0; f < t.cols(); ++f) {
    const Eigen::Vector3d a = positions.col(t(0, f));
    area += 0.5 * (positions.col(t(1, f)) - a).cross(positions.col(t(2, f)) - a).norm();
  }
  return area;
}

Eigen::Matrix3Xd smoothMeshPositions(const MeshTopology& topology, const Eigen::Matrix3Xd& world,
                                     const MeshSmoothingParameters& p, MeshSmoothingReport* report,
                                     const SmoothingProgress& progress) {
  const int n = topology.numVertices();
  if (world.cols() == n) requireFinite(world);
  // The flow moves the positions about the mesh's local origin (mesh/local_cloud.h; exact):
  // far from the origin the solves' residuals would be relative to |x|, not to the mesh's size.
  const Eigen::Vector3d origin = localOrigin(world);
  const Eigen::Matrix3Xd positions = world.colwise() - origin;
  if (n == 0 || topology.numTriangles() == 0) throw InvalidMeshException("mesh has no triangles");
  if (positions.cols() != n) throw InvalidMeshException("positions do not match the mesh");
  requireFinite(positions);
  if (!(p.time_step > 0.0) || !std::isfinite(p.time_step)) badArgument("time step must be > 0");
  if (p.iterations < 1) badArgument("iterations must be at least 1");
  if (p.scheme == SmoothingScheme::Taubin && !(p.taubin_mu < -p.time_step)) {
    badArgument("Taubin's mu must be below -lambda (e.g. lambda 0.5, mu -0.53)");
  }
  if (!(p.thickness_limit >= 0.0) || !std::isfinite(p.thickness_limit)) {
    badArgument("the thickness limit must be >= 0 (0: none)");
  }
  if (!std::isfinite(p.time_step * p.iterations)) badArgument("the total time is not finite");
  if (p.shrinkage != ShrinkageCorrection::None && p.boundary == BoundaryCondition::Fixed) {
    badArgument("a shrinkage correction rescales the whole mesh: it cannot keep a fixed boundary");
  }
  if (p.shrinkage == ShrinkageCorrection::PreserveVolume && !isClosedAndOriented(topology)) {
    badArgument("volume preservation needs a closed, consistently oriented mesh");
  }

  std::vector<char> fixed(n, 0);
  if (p.boundary == BoundaryCondition::Fixed) {
    for (int v = 0; v < n; ++v) fixed[v] = topology.isBoundary(v);
  }
  detail::LaplacianFlow flow(n, std::move(fixed), p.solver, p.implicit_solver);
  flow.planSteps(p.iterations, p.weight_update == WeightUpdate::Frozen ? 1 : p.iterations);
  MeshSmoothingReport r;
  // The input's operator: the flow's first (or only) one, and the slowdown's.
  Eigen::SparseMatrix<double> stiffness =
      laplacian(topology, positions, p.weights, LaplacianForm::Summed);
  Eigen::VectorXd average = averageOf(stiffness, topology, positions, p.mass, p.average);
  // Thin parts move more slowly (see the header): s_i multiplies vertex i's mass.
  Eigen::ArrayXd slowdown = Eigen::ArrayXd::Ones(n);
  if (p.thickness_limit > 0.0 && p.average == FlowAverage::Area &&
      p.scheme != SmoothingScheme::Taubin) {
    slowdown = thinPartSlowdown(topology, positions, stiffness, average, p);
    r.thin_vertices = static_cast<int>((slowdown > 1.0 / 0.9).count());
    r.mean_time_fraction = slowdown.inverse().mean();
  }
  flow.setOperator(std::move(stiffness), (average.array() * slowdown).matrix());

  // The before and after measures are for the report, and the shrinkage corrections' targets.
  const bool closed = isClosedAndOriented(topology);
  r.solver = flow.backend();
  r.area_before = surfaceArea(topology, positions);
  if (closed) r.volume_before = enclosedVolume(topology, positions);
  // Collapse to within h of the centroid is only news for a mesh that was larger than that.
  const double h = meanEdgeLength(topology, positions);
  const double within =
      ((positions.colwise() - surfaceCentroid(topology, positions)).colwise().norm().array() >= h)
              .any()
          ? h
          : 0.0;
  if (report) r.quality_before = triangleQuality(topology, positions);

  Eigen::Matrix3Xd current = positions;
  Eigen::MatrixXd values = positions.transpose();  // one column per coordinate
  r.fixed_vertices = n - flow.numFree();
  for (int iteration = 1; iteration <= p.iterations; ++iteration) {
    if (iteration > 1 && p.weight_update == WeightUpdate::EveryIteration) {
      stiffness = laplacian(topology, current, p.weights, LaplacianForm::Summed);
      average = averageOf(stiffness, topology, current, p.mass, p.average);
      flow.setOperator(std::move(stiffness), (average.array() * slowdown).matrix());
    }
    // A degree average belongs to the stiffness: with it frozen, nothing follows the surface.
    if (iteration > 1 && p.weight_update == WeightUpdate::FrozenStiffness &&
        p.average == FlowAverage::Area)
      flow.setMass((lumpedMass(topology, current, p.mass).array() * slowdown).matrix());
    if (p.scheme == SmoothingScheme::Explicit) {
      flow.explicitStep(values, p.time_step);
    } else if (p.scheme == SmoothingScheme::Taubin) {
      flow.explicitStep(values, p.time_step);
      flow.explicitStep(values, p.taubin_mu);
    } else {
      try {
        flow.implicitStep(values, p.time_step);
      } catch (const pcl::ComputeFailedException& e) {
        failedAt(iteration, errorDescription(e));
      }
    }
    current = values.transpose();
    if (!current.allFinite()) {
      failedAt(iteration, p.scheme != SmoothingScheme::Implicit
                              ? "non-finite positions (the explicit or Taubin steps are "
                                "unstable: use smaller steps or the implicit scheme)"
                              : "non-finite positions");
    }
    requireNotCollapsed(topology, current, r.area_before, r.volume_before, within, iteration);
    if (p.shrinkage != ShrinkageCorrection::None) {
      double scale;
      if (p.shrinkage == ShrinkageCorrection::PreserveVolume) {
        const double volume = enclosedVolume(topology, current);
        if (!(volume * r.volume_before > 0.0)) failedAt(iteration, "the volume vanished");
        scale = std::cbrt(r.volume_before / volume);
      } else {
        const double area = surfaceArea(topology, current);
        if (!(area > 0.0)) failedAt(iteration, "the area vanished");
        scale = std::sqrt(r.area_before / area);
      }
      const Eigen::Vector3d centre = surfaceCentroid(topology, current);
      current = ((current.colwise() - centre) * scale).colwise() + centre;
      values = current.transpose();
    }
    r.iterations = iteration;
    if (progress) progress(iteration, p.iterations);
  }
  r.implicit_solver = flow.implicitSolver();
  r.conjugate_gradient_iterations = flow.conjugateGradientIterations();
  if (report) {
    r.area_after = surfaceArea(topology, current);
    r.quality_after = triangleQuality(topology, current);
    if (closed) r.volume_after = enclosedVolume(topology, current);
    *report = r;
  }
  return current.colwise() + origin;
}

void MeshSmoothing::process(pcl::PolygonMesh& output) {
  if (!input_) {
    throw pcl::BadArgumentException("no input mesh");
  }
  const MeshTopology topology(*input_);
  const Eigen::Matrix3Xd smoothed = smoothMeshPositions(topology, vertexPositions(input_->cloud),
                                                        parameters_, &report_, progress_);
  pcl::PolygonMesh result = *input_;
  setVertexPositions(result.cloud, smoothed);
  output = std::move(result);
}

}  // namespace pcl_ddg
