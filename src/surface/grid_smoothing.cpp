#include "pcl_ddg/surface/grid_smoothing.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "laplacian_flow.h"

namespace pcl_ddg {
namespace {

[[noreturn]] void badArgument(const std::string& what) {
  throw pcl::BadArgumentException(what);
}

}  // namespace

Eigen::Matrix3Xd smoothOrganizedPositions(const Eigen::Matrix3Xd& positions, int width, int height,
                                          const Eigen::Vector3d& origin,
                                          const GridSmoothingParameters& p,
                                          GridSmoothingReport* report) {
  if (width < 1 || height < 2) badArgument("the cloud is not organized (height must be > 1)");
  const int n = width * height;
  if (positions.cols() != n) badArgument("positions do not match width x height");
  if (!(p.time_step > 0.0) || !std::isfinite(p.time_step)) badArgument("time step must be > 0");
  if (p.iterations < 1) badArgument("iterations must be at least 1");
  if (p.scheme == SmoothingScheme::Taubin)
    badArgument("grid smoothing is explicit or implicit, not Taubin");
  if (!(p.max_depth_jump > 0.0)) badArgument("max depth jump must be > 0");
  if (!origin.allFinite()) badArgument("the sensor origin is not finite");

  // Ranges and unit rays; holes get range 0 in the flow (they are never coupled) and stay NaN. A
  // point at the sensor origin has no ray to move along: it is not coupled and stays where it is.
  GridSmoothingReport r;
  Eigen::MatrixXd range = Eigen::MatrixXd::Zero(n, 1);
  Eigen::Matrix3Xd rays(3, n);
  std::vector<char> valid(n, 0);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = positions.col(i) - origin;
    const double length = d.norm();
    if (!std::isfinite(length)) continue;
    if (!(length > 0.0)) {
      ++r.points_at_origin;
      continue;
    }
    valid[i] = 1;
    range(i) = length;
    rays.col(i) = d / length;
    ++r.valid_pixels;
  }
  r.holes = n - r.valid_pixels - r.points_at_origin;

  // The 5-point graph Laplacian of the coupled pixels (every valid pixel keeps a diagonal entry).
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(r.valid_pixels) * 5);
  const auto couple = [&](int i, int j) {
    if (!valid[i] || !valid[j]) return;
    if (std::abs(range(i) - range(j)) > p.max_depth_jump * std::min(range(i), range(j))) {
      ++r.cut_pairs;
      return;
    }
    entries.emplace_back(i, j, 1.0);
    entries.emplace_back(j, i, 1.0);
    entries.emplace_back(i, i, -1.0);
    entries.emplace_back(j, j, -1.0);
    ++r.coupled_pairs;
  };
  for (int row = 0; row < height; ++row) {
    for (int column = 0; column < width; ++column) {
      const int i = row * width + column;
      if (valid[i]) entries.emplace_back(i, i, 0.0);
      if (column + 1 < width) couple(i, i + 1);
      if (row + 1 < height) couple(i, i + width);
    }
  }
  Eigen::SparseMatrix<double> laplacian(n, n);
  laplacian.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd mass(n);
  for (int i = 0; i < n; ++i) mass[i] = valid[i] ? 1.0 : 0.0;

  detail::LaplacianFlow flow(n, {}, p.solver, p.implicit_solver);
  flow.planSteps(p.iterations, 1);
  flow.setOperator(std::move(laplacian), std::move(mass));
  for (int iteration = 1; iteration <= p.iterations; ++iteration) {
    if (p.scheme == SmoothingScheme::Explicit) {
      flow.explicitStep(range, p.time_step);
    } else {
      flow.implicitStep(range, p.time_step);
    }
    if (!range.allFinite()) {
      throw pcl::ComputeFailedException("grid smoothing step " + std::to_string(iteration) +
                                        ": non-finite ranges");
    }
  }

  Eigen::Matrix3Xd result(3, n);
  for (int i = 0; i < n; ++i) {
    result.col(i) = valid[i] ? Eigen::Vector3d(origin + range(i) * rays.col(i))
                    : positions.col(i).allFinite()
                        ? Eigen::Vector3d(positions.col(i))
                        : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  if (report) *report = r;
  return result;
}

}  // namespace pcl_ddg
