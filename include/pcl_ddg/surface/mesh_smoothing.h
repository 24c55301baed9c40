#pragma once
/** \file
 * Laplacian smoothing of a mesh's vertex positions: the mean-curvature-like flow dx/dt = M^-1 L x.
 *
 *   Explicit  x <- x + tau M^-1 L x per iteration (forward Euler). Cheap, but stable only for
 *             tau below about 2 / |lambda_max(M^-1 L)|, i.e. a fraction of h^2 (h = mean edge
 *             length): larger steps make every iteration amplify the finest wrinkles, and the
 *             positions blow up (raised as an exception naming the iteration).
 *   Implicit  (M - tau L) x' = M x (backward Euler, Desbrun et al. 1999): one sparse Cholesky
 *             or conjugate-gradient solve per iteration (implicit_solver.h; by default whichever
 *             costs less for the run), x, y, z as three right-hand sides. Stable for any tau, so
 *             one large step replaces thousands of small ones.
 *   Taubin    x <- x + lambda M^-1 L x, then x <- x + mu M^-1 L x (mu < -lambda < 0) per
 *             iteration (Taubin 1995, "A signal processing approach to fair surface design"): a
 *             low-pass filter that, unlike the flow, does not shrink the surface; lambda is
 *             time_step, mu taubin_mu. Usually with the umbrella operator (below): lambda 0.5,
 *             mu -0.53 and tens of iterations.
 * L is the summed uniform or cotangent Laplacian (laplacian.h). M averages it: by default
 * (FlowAverage::Area) the lumped mass of the chosen type, so M^-1 L approximates the
 * Laplace-Beltrami operator and tau is a time in length^2; or (FlowAverage::Degree) each vertex's
 * total weight D = -diag(L), so D^-1 L x is the weighted mean of the neighbours minus x, with
 * uniform weights the umbrella operator, and tau is dimensionless: explicit steps are stable up to
 * tau = 1 whatever the triangles' areas (a scan's tiny vertex areas put the Area bound at 1e-3 h^2
 * and below). By default L and M are frozen at the input (WeightUpdate below): rebuilding cotangent
 * weights every iteration is the singular mean-curvature flow, which pinches triangles into slivers
 * within a few large steps; M alone can follow the positions (Kazhdan et al. 2012, "Can
 * mean-curvature flow be modified to be non-singular?"; libigl's smoothing tutorial). With
 * Cholesky the system's pattern is analysed once; frozen, it is factorised once, otherwise
 * refactorised per iteration. The report gives the triangles' angle quality before and after
 * (slivers: a corner under 1 deg).
 *
 * Thin parts. Any Laplacian flow draws a tube of radius a towards its axis at a rate of about
 * 1/a^2 (the circle's lowest mode): a total time t = n tau shrinks it by about exp(-t / a^2) (the
 * implicit steps by (1 + tau / a^2)^-n), and a handle, leg or horn a few edges thick collapses into
 * slivers within a few large steps, whatever follows the surface (WeightUpdate). With
 * thickness_limit = c (default 0.5) the vertices where the solid is thin move more slowly: vertex
 * i's mass is multiplied by s_i = max(1, n tau / (c r_i^2)), r_i its inner-ball radius at the
 * input, so that its total time n tau / s_i is at most about c r_i^2 (a tube keeps about
 * e^-0.5 = 0.6 of its radius, the implicit steps more) while the rest of the surface gets the full
 * time. log s is then smoothed by the same flow (one more implicit solve, the input's operator) for
 * n tau, at most four times what the median vertex gets: a slowdown that changed faster than the
 * flow smooths would itself roughen a curved surface (slowed vertices shrink less than their
 * neighbours; a single noise bump of depth e on edges h reads as r = h^2 / (2 e)), and far beyond
 * the thick parts' own limit a longer smoothing would even out thin and thick parts.
 * M s stays diagonal and positive, so M s - tau L is still symmetric positive definite and the
 * explicit bound only grows. Three implicit cotangent steps of 2 h^2 with the volume preserved
 * (bench/bench_smoothing_health.py): on coarse genus-2..4 surfaces with tubes of radius 1.5-2.4 h
 * and on the shared scans, new slivers at most 0.1 % of the faces (without the limit up to 1.7 %,
 * the cow 7.5 %); the scans' umbrella measure still drops by a third or more. The price: features
 * and noise narrower than about sqrt(n tau / c) are smoothed for less time too (a unit sphere of
 * 642 vertices with radial noise of 0.1 h, five steps of h^2: RMS error 0.0151 -> 0.0084 against
 * 0.0037 without the limit); thickness_limit = 0 smooths everything for the whole time.
 *
 * Boundary vertices move (Free, default) or keep their position (Fixed). Vertices without mass
 * (isolated, or only on degenerate triangles) never move. Laplacian flow shrinks a surface; the
 * optional correction rescales the result about its mass-weighted centroid after every iteration
 * so that the enclosed volume (closed, consistently oriented meshes) or the surface area is that
 * of the input.
 *
 * Errors: InvalidMeshException for an empty mesh or non-finite input; pcl::BadArgumentException for
 * bad parameters (tau <= 0, Taubin's mu not below -tau, iterations < 1, a negative or non-finite
 * thickness limit, volume correction on an
 * open mesh, a correction with a fixed boundary); pcl::ComputeFailedException when an iteration
 * produces a non-finite position or a singular system, naming the iteration;
 * SurfaceCollapseException when a step collapses the surface (before any correction): area or
 * enclosed volume below 1e-6 of the input's, or every vertex within one mean edge length h of the
 * input of the centroid. A correction would only blow such a remnant up again. The input is never
 * modified.
 */
#include <pcl/PolygonMesh.h>
#include <pcl/exceptions.h>

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"
#include "pcl_ddg/operators/laplacian.h"
#include "pcl_ddg/operators/mass_matrix.h"
#include "pcl_ddg/operators/sparse_cholesky.h"
#include "pcl_ddg/surface/implicit_solver.h"

namespace pcl_ddg {

/** A step too large for the surface: it collapsed to (nearly) a point, curve or sliver. */
class SurfaceCollapseException : public pcl::ComputeFailedException {
 public:
  explicit SurfaceCollapseException(const std::string& description)
      : pcl::ComputeFailedException(description) {}
};

enum class SmoothingScheme { Explicit, Implicit, Taubin };
/** What divides the Laplacian: vertex areas (the geometric flow) or vertex degrees (the umbrella
 *  operator with uniform weights); see above. */
enum class FlowAverage { Area, Degree };
/** What of the operator follows the moving surface: nothing (Frozen, the default), the mass only
 *  (FrozenStiffness: Kazhdan et al. 2012's conformalized mean-curvature flow), or the Laplacian
 *  and the mass (EveryIteration: mean-curvature flow, which pinches thin parts into slivers).
 *  Frozen is the default: without the thickness limit it makes the fewest slivers on coarse scans
 *  with thin parts (bench/bench_smoothing_health.py), and it factorises once for all iterations. */
enum class WeightUpdate { FrozenStiffness, Frozen, EveryIteration };
enum class BoundaryCondition { Free, Fixed };
enum class ShrinkageCorrection { None, PreserveVolume, PreserveArea };

struct MeshSmoothingParameters {
  SmoothingScheme scheme = SmoothingScheme::Implicit;
  LaplacianWeights weights = LaplacianWeights::Cotangent;
  MassType mass = MassType::MixedVoronoi;  ///< with FlowAverage::Area
  FlowAverage average = FlowAverage::Area;
  /** tau (Taubin: lambda): Area in length^2 (e.g. 0.1 * h^2 explicit, 10 * h^2 implicit), Degree
   *  dimensionless (e.g. 0.5) */
  double time_step = 0.0;
  double taubin_mu = -0.53;  ///< Taubin's second factor, in time_step's units
  int iterations = 1;
  WeightUpdate weight_update = WeightUpdate::Frozen;
  /** Thin parts: a vertex whose inner ball (inner_ball.h; half the local thickness) has radius r
   *  smooths for at most about thickness_limit * r^2 of time in all; see the header comment. 0: no
   * limit. Only with FlowAverage::Area and the explicit or implicit scheme (Taubin's filter does
   * not shrink). */
  double thickness_limit = 0.5;
  BoundaryCondition boundary = BoundaryCondition::Free;
  ShrinkageCorrection shrinkage = ShrinkageCorrection::None;
  ImplicitSolver implicit_solver = ImplicitSolver::Automatic;
  CholeskyBackend solver = CholeskyBackend::Automatic;  ///< when the implicit solver factorises
};

struct MeshSmoothingReport {
  int iterations = 0;
  ImplicitSolver implicit_solver = ImplicitSolver::Automatic;  ///< the one used (implicit)
  CholeskyBackend solver = CholeskyBackend::Automatic;         ///< the one used by Cholesky
  long conjugate_gradient_iterations = 0;                      ///< over all steps and columns
  int fixed_vertices = 0;                                      ///< fixed boundary + massless
  int thin_vertices = 0;            ///< vertices thickness_limit left under 0.9 of the time
  double mean_time_fraction = 1.0;  ///< of the time asked, what the vertices got on average
  double volume_before = 0.0, volume_after = 0.0;  ///< closed meshes (else 0)
  double area_before = 0.0, area_after = 0.0;
  TriangleQuality quality_before, quality_after;
};

/** Called after every iteration with (iterations done, total). */
using SmoothingProgress = std::function<void(int, int)>;

/** Smoothed copy of positions (3 x N); see the header comment. */
Eigen::Matrix3Xd smoothMeshPositions(const MeshTopology& topology,
                                     const Eigen::Matrix3Xd& positions,
                                     const MeshSmoothingParameters& parameters,
                                     MeshSmoothingReport* report = nullptr,
                                     const SmoothingProgress& progress = {});

/**
 * A time step up to which the explicit scheme is stable on this mesh: 2 / max_i sum_j |L_ij| / m_i,
 * the Gershgorin bound on the spectrum of M^-1 L (sufficient; the sharp limit is usually 1-3x
 * larger). Averaged by Area: in length^2, on scans often 1e-3 h^2 or less, because of tiny vertex
 * areas. Averaged by Degree: dimensionless, 1 whenever no weight is negative (always for uniform
 * weights: the umbrella operator).
 */
double explicitStabilityLimit(const MeshTopology& topology, const PositionsRef& positions,
                              LaplacianWeights weights = LaplacianWeights::Cotangent,
                              MassType mass = MassType::MixedVoronoi,
                              FlowAverage average = FlowAverage::Area);

/** Volume enclosed by a closed, consistently oriented mesh (divergence theorem; positive for
 *  outward faces). */
double enclosedVolume(const MeshTopology& topology, const PositionsRef& positions);

/** The same per connected component (indexed as MeshTopology::vertexComponent): the volume each
 *  closed component encloses, its tetrahedra taken to its own vertices' mean (components far
 *  apart lose no digits); their sum is enclosedVolume. An open component's entry depends on that
 *  point and measures nothing. Throws InvalidMeshException if positions do not match the mesh. */
std::vector<double> componentVolumes(const MeshTopology& topology, const PositionsRef& positions);

/** Sum of the triangle areas. */
double surfaceArea(const MeshTopology& topology, const PositionsRef& positions);

/**
 * The same as a mesh processor with pcl::MeshProcessing's shape (without its VTK dependency):
 * setInputMesh, setters, process(output). The output is the input mesh with new x, y, z (in the
 * input's field types; every other field and the polygons kept).
 */
class MeshSmoothing {
 public:
  void setInputMesh(const pcl::PolygonMeshConstPtr& mesh) { input_ = mesh; }
  pcl::PolygonMeshConstPtr getInputMesh() const { return input_; }

  void setParameters(const MeshSmoothingParameters& parameters) { parameters_ = parameters; }
  const MeshSmoothingParameters& getParameters() const { return parameters_; }
  void setScheme(SmoothingScheme scheme) { parameters_.scheme = scheme; }
  void setWeights(LaplacianWeights weights) { parameters_.weights = weights; }
  void setMassType(MassType mass) { parameters_.mass = mass; }
  void setAverage(FlowAverage average) { parameters_.average = average; }
  void setTaubinMu(double mu) { parameters_.taubin_mu = mu; }
  void setTimeStep(double tau) { parameters_.time_step = tau; }
  void setNumberOfIterations(int iterations) { parameters_.iterations = iterations; }
  void setWeightUpdate(WeightUpdate update) { parameters_.weight_update = update; }
  void setThicknessLimit(double limit) { parameters_.thickness_limit = limit; }
  void setBoundaryCondition(BoundaryCondition boundary) { parameters_.boundary = boundary; }
  void setShrinkageCorrection(ShrinkageCorrection correction) {
    parameters_.shrinkage = correction;
  }
  void setImplicitSolver(ImplicitSolver solver) { parameters_.implicit_solver = solver; }
  void setSolver(CholeskyBackend solver) { parameters_.solver = solver; }
  void setProgressCallback(SmoothingProgress progress) { progress_ = std::move(progress); }

  /** Throws as smoothMeshPositions; output is untouched on failure. */
  void process(pcl::PolygonMesh& output);

  const MeshSmoothingReport& getReport() const { return report_; }

 private:
  pcl::PolygonMeshConstPtr input_;
  MeshSmoothingParameters parameters_;
  SmoothingProgress progress_;
  MeshSmoothingReport report_;
};

}  // namespace pcl_ddg
