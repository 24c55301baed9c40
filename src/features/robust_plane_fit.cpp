#include "pcl_ddg/features/robust_plane_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "pcl_ddg/features/plane_fit.h"
#include "point_moments.h"
#include "vector_lanes.h"

namespace pcl_ddg {

namespace {

constexpr int kSmallestScale = 16;     ///< nested scales 16, 24, 32, 48, 64, 96, ... and all
constexpr int kAnchorNeighbours = 8;   ///< planes pass through the centroid of these
constexpr int kSeedNeighbours = 6;     ///< planes through the query and two of these
constexpr int kScoredNeighbours = 64;  ///< the least median of squares is over these nearest
constexpr int kFewLargest = 8;  ///< a median this near the top of its residuals: no selection
constexpr double kMadToSigma = 1.4826;
constexpr double kBand = 3.0;           ///< inliers are within this many sigma-hat of the plane
constexpr double kNoiseFloor = 1e-6;    ///< of the neighbourhood's radius
constexpr double kScaleVariance = 2.0;  ///< a plane's residual variance over a quadric's
constexpr double kThroughQuery = 0.5;   ///< a plane through the query must halve the median
constexpr double kSmooth = 0.01;        ///< a quadric leaves less of a plane's residual variance
constexpr int kMaxRefinements = 5;
constexpr double kConverged = 1e-5;  ///< normal change (radians) that ends the refinement

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
};

/** The median of |n . (x_i - c)| over the first count columns of x (element count / 2 of them
 *  sorted) when it is below `below`, else infinity. Most planes tried are worse than the best so
 *  far: counting the residuals below it tells so (fewer than count / 2 + 1 of them), as soon as
 *  too few are left to reach that, without the selection. A plane kept has its median among the
 *  residuals below `below` (they are the smallest), which are selected from alone: the same value
 *  as a selection from all. (A NaN residual, from coordinates near overflow, selects from all.) */
double medianResidualBelow(const Eigen::Matrix3Xd& x, int count, const Plane& plane, double below,
                           std::vector<double>& residuals, std::vector<double>& smaller) {
  residuals.resize(static_cast<std::size_t>(count));
  smaller.resize(static_cast<std::size_t>(count));
  const double offset = plane.normal.dot(plane.centroid);
  const int needed = count / 2 + 1;  // residuals under `below` for a median under it
  int under = 0;
  bool nan = false;
  for (int i = 0; i < count; ++i) {
    const double r = std::abs(plane.normal.dot(x.col(i)) - offset);
    residuals[i] = r;
    smaller[under] = r;
    under += r < below;
    nan = nan || std::isnan(r);
    if (!nan && under + (count - 1 - i) < needed) return std::numeric_limits<double>::infinity();
  }
  if (!nan) {
    // The median is the `largest`-th largest of them: few when the plane is about as good as the
    // best so far (most planes that get here), found by insertion into a short descending list.
    const int largest = under - count / 2;
    if (largest > kFewLargest) {
      const auto middle = smaller.begin() + count / 2;
      std::nth_element(smaller.begin(), middle, smaller.begin() + under);
      return *middle;
    }
    double top[kFewLargest];
    int held = 0;
    for (int i = 0; i < under; ++i) {
      const double r = smaller[i];
      if (held == largest && !(r > top[held - 1])) continue;
      int at = held < largest ? held++ : held - 1;
      for (; at > 0 && top[at - 1] < r; --at) top[at] = top[at - 1];
      top[at] = r;
    }
    return top[largest - 1];
  }
  const auto middle = residuals.begin() + count / 2;
  std::nth_element(residuals.begin(), middle, residuals.end());
  return *middle < below ? *middle : std::numeric_limits<double>::infinity();
}

using detail::PointMoments;

/** Whether a point lies within band of the plane whose offset n . c is given. (|r| < band, not
 *  |r / band| < 1: the same answer for every r and every band >= 0 or NaN, all this file passes, a
 * correctly rounded quotient below 1 being the exact one's, without a division per point.) */
bool inBand(const Plane& plane, double offset, const Eigen::Vector3d& point, double band) {
  return std::abs(plane.normal.dot(point) - offset) < band;
}

/** Moments of those of the first count columns of x within band of plane; inside[i] says
 *  whether column i is one of them. */
PointMoments within(const Eigen::Matrix3Xd& x, int count, const Plane& plane, double band,
                    std::vector<char>& inside) {
  PointMoments m;
  inside.resize(static_cast<std::size_t>(count));
  const double offset = plane.normal.dot(plane.centroid);
  for (int i = 0; i < count; ++i) {
    inside[i] = inBand(plane, offset, x.col(i), band);
    if (inside[i]) m.add(x.col(i));
  }
  return m;
}

/** How many of the first count columns of x lie within band of plane. */
int countWithin(const Eigen::Matrix3Xd& x, int count, const Plane& plane, double band) {
  const double offset = plane.normal.dot(plane.centroid);
  int inside = 0;
  for (int i = 0; i < count; ++i) inside += inBand(plane, offset, x.col(i), band);
  return inside;
}

/** A quadric's frame: origin, then t1, t2, n (NestedQuadric). */
struct Frame {
  double origin[3], t1[3], t2[3], n[3];
};

/** To each of the 21 sums of a quadric's normal matrix's lower triangle (all its solver reads)
 *  a_i a_j, to the right side w a_i and to the squares w^2, over columns begin .. end - 1 of the
 *  3 x n matrix x, a = (u^2, uv, v^2, u, v, 1) and (u, v, w) = (x - origin) / scale in the frame.
 *  The sums stay in locals over the range (as an Eigen row built in memory and read back in pairs,
 *  each point stalled on the store), in the order they were always added; a free function so
 *  that it compiles for AVX2 too (vector_lanes.h: the same roundings). The dot products are
 *  (a0 b0 + a1 b1) + a2 b2, as Eigen forms them. */
PCL_DDG_WIDE_LANES void addQuadricTerms(const double* x, int begin, int end, const Frame& frame,
                                        double scale, double* lower, double* right_side,
                                        double& squares_sum) {
  constexpr int kLower = 21;
  double sums[kLower], right[6];
  for (int s = 0; s < kLower; ++s) sums[s] = lower[s];
  for (int i = 0; i < 6; ++i) right[i] = right_side[i];
  double squares = squares_sum;
  const auto dot = [](const double* a, const double* b) {
    return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2];
  };
  for (int i = begin; i < end; ++i) {
    const double* p = x + 3 * static_cast<std::ptrdiff_t>(i);
    const double d[3] = {(p[0] - frame.origin[0]) / scale, (p[1] - frame.origin[1]) / scale,
                         (p[2] - frame.origin[2]) / scale};
    const double u = dot(d, frame.t1), v = dot(d, frame.t2), w = dot(d, frame.n);
    const double a[6] = {u * u, u * v, v * v, u, v, 1.0};
    int s = 0;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c <= r; ++c) sums[s++] += a[r] * a[c];
    for (int r = 0; r < 6; ++r) right[r] += w * a[r];
    squares += w * w;
  }
  for (int s = 0; s < kLower; ++s) lower[s] = sums[s];
  for (int i = 0; i < 6; ++i) right_side[i] = right[i];
  squares_sum = squares;
}

/** The least-squares height-field quadric w = a u^2 + b uv + c v^2 + d u + e v + f over the
 *  points added so far, in a fixed frame (u, v, w along t1, t2, n about origin, in units of
 *  scale): its residual sum of squares at any prefix of the nearest-first neighbours. */
class NestedQuadric {
 public:
  NestedQuadric(const Plane& frame, double scale)
      : t1_(frame.normal.unitOrthogonal()),
        t2_(frame.normal.cross(t1_)),
        normal_(frame.normal),
        origin_(frame.centroid),
        scale_(scale) {}

  /** Adds the columns begin .. end - 1 of x (addQuadricTerms). */
  void add(const Eigen::Matrix3Xd& x, int begin, int end) {
    const Frame frame{{origin_.x(), origin_.y(), origin_.z()},
                      {t1_.x(), t1_.y(), t1_.z()},
                      {t2_.x(), t2_.y(), t2_.z()},
                      {normal_.x(), normal_.y(), normal_.z()}};
    addQuadricTerms(x.data(), begin, end, frame, scale_, lower_, right_.data(), squares_);
    count_ += end - begin;
  }
  /** Residual variance SSR / (m - 6) in length^2; NaN when the system is singular. */
  double variance() const {
    if (count_ <= 6) return std::numeric_limits<double>::quiet_NaN();
    Eigen::Matrix<double, 6, 6> normal_matrix;
    int s = 0;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c <= r; ++c) normal_matrix(r, c) = lower_[s++];
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(
        normal_matrix.selfadjointView<Eigen::Lower>());
    if (solver.info() != Eigen::Success || !solver.isPositive())
      return std::numeric_limits<double>::quiet_NaN();
    const double residual = std::max(squares_ - right_.dot(solver.solve(right_)), 0.0);
    return residual / (count_ - 6) * scale_ * scale_;
  }

 private:
  using Row = Eigen::Matrix<double, 6, 1>;
  Eigen::Vector3d t1_, t2_, normal_, origin_;
  double scale_;
  static constexpr int kLower = 21;  ///< entries (r, c <= r) of the 6 x 6 normal matrix, by row
  double lower_[kLower] = {};
  Row right_ = Row::Zero();
  double squares_ = 0.0;
  int count_ = 0;
};

}  // namespace

RobustPlaneFit fitRobustPlane(const Eigen::Matrix3Xd& points, int count) {
  RobustPlaneFit result;
  if (count < 3) return result;

  // Buffers reused by each thread's next neighbourhood: a fit takes microseconds.
  thread_local std::vector<std::pair<double, int>> by_distance;
  thread_local Eigen::Matrix3Xd sorted;
  thread_local std::vector<double> residuals, smaller;
  thread_local std::vector<char> inside, was_inside;
  // The neighbours nearest first: as given when they are (k-d tree searches give them so), else
  // a sorted copy (ties keep their order).
  double farthest = points.col(0).squaredNorm();
  int in_order = 1;
  for (; in_order < count; ++in_order) {
    const double distance = points.col(in_order).squaredNorm();
    if (distance < farthest) break;
    farthest = distance;
  }
  if (in_order < count) {
    by_distance.resize(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) by_distance[i] = {points.col(i).squaredNorm(), i};
    std::stable_sort(by_distance.begin(), by_distance.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    sorted.resize(3, count);
    for (int i = 0; i < count; ++i) sorted.col(i) = points.col(by_distance[i].second);
    farthest = by_distance.back().first;
  }
  const Eigen::Matrix3Xd& x = in_order < count ? sorted : points;
  const double radius = std::sqrt(farthest);
  const double floor = kNoiseFloor * radius;

  // 1. Nested least-squares planes, through the centroid of the nearest few (near the surface:
  //    through its own centroid a large plane lies off a curved surface).
  struct Scale {
    int k;
    Plane plane;
    double l0;
  };
  //    Their covariances first, then their planes together in the CPU's vector lanes.
  thread_local std::vector<Scale> scales;
  thread_local std::vector<double> xx, xy, xz, yy, yz, zz, trace, nx, ny, nz, variation;
  thread_local std::vector<std::uint8_t> valid;
  thread_local std::vector<int> sizes;
  for (auto* entries : {&xx, &xy, &xz, &yy, &yz, &zz, &trace}) entries->clear();
  sizes.clear();
  PointMoments nested;
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
  int next = std::min(kSmallestScale, count);
  for (int i = 0; i < count; ++i) {
    nested.add(x.col(i));
    if (nested.count() == std::min(kAnchorNeighbours, count)) anchor = nested.centroid();
    if (nested.count() != next && nested.count() != count) continue;
    if (nested.count() == next) next = (next & (next - 1)) == 0 ? next * 3 / 2 : next * 4 / 3;
    const Eigen::Matrix3d covariance = nested.covariance();
    xx.push_back(covariance(0, 0)), xy.push_back(covariance(0, 1));
    xz.push_back(covariance(0, 2)), yy.push_back(covariance(1, 1));
    yz.push_back(covariance(1, 2)), zz.push_back(covariance(2, 2));
    trace.push_back(covariance.trace());
    sizes.push_back(nested.count());
  }
  const int tried = static_cast<int>(sizes.size());
  for (auto* entries : {&nx, &ny, &nz, &variation}) entries->resize(sizes.size());
  valid.resize(sizes.size());
  fitPlaneNormals(tried, {xx.data(), xy.data(), xz.data(), yy.data(), yz.data(), zz.data()},
                  {nx.data(), ny.data(), nz.data(), variation.data(), valid.data()});
  scales.clear();
  for (int j = 0; j < tried; ++j)
    if (valid[j])
      scales.push_back(
          {sizes[j], {Eigen::Vector3d(nx[j], ny[j], nz[j]), anchor}, variation[j] * trace[j]});

  // 2. The scale (after Mitra and Nguyen 2003): the largest at which a plane explains the
  //    neighbours as well as a quadric does, up to kScaleVariance (an F-test of the nested
  //    models): there the residual is noise, not curvature, and more neighbours only average it.
  //    Clean curved data keeps the smallest scale, noisy data nearly flat at its size all.
  //    The quadric's sums at every scale first, then its variances from the largest scale down
  //    to the first explained (noisy data solve one or two of the six systems, not all).
  int chosen = scales.empty() ? -1 : 0;
  bool smooth = false;  // the smallest scale is a smooth surface: a quadric explains it
  if (!scales.empty()) {
    thread_local std::vector<NestedQuadric> prefixes;
    prefixes.clear();
    NestedQuadric quadric(scales.back().plane, radius);
    int added = 0;
    for (const Scale& scale : scales) {
      quadric.add(x, added, scale.k);
      added = scale.k;
      prefixes.push_back(quadric);
    }
    // The plane's residual variance at scale j and the quadric's (NaN: no quadric, so neither
    // smooth nor explained by the plane).
    const auto planeVariance = [&](std::size_t j) {
      return scales[j].l0 * scales[j].k / std::max(scales[j].k - 3, 1);
    };
    const auto curvedVariance = [&](std::size_t j) {
      const double fitted = prefixes[j].variance();
      return std::isnan(fitted) ? fitted : std::max(fitted, floor * floor);
    };
    const double smallest = curvedVariance(0);
    smooth = smallest < kSmooth * planeVariance(0);
    for (std::size_t j = scales.size(); j-- > 0;) {
      if (planeVariance(j) <= kScaleVariance * (j == 0 ? smallest : curvedVariance(j))) {
        chosen = static_cast<int>(j);
        break;
      }
    }
  }
  const int used = chosen < 0 ? count : scales[chosen].k;

  // 3. Least median of squares over the nearest of that scale: the nested planes up to it, or
  //    a plane through the query and two of its nearest neighbours that halves their median
  //    (a point on a face of an edge spans its own face with them).
  const int scored = std::min(used, kScoredNeighbours);
  double best_median = std::numeric_limits<double>::infinity();
  Plane plane;
  for (int j = 0; j <= chosen; ++j) {
    const double median =
        medianResidualBelow(x, scored, scales[j].plane, best_median, residuals, smaller);
    if (median < best_median) {
      best_median = median;
      plane = scales[j].plane;
    }
  }
  const double nested_median = best_median;
  // Not on smooth surfaces, where a plane through the point that cuts the surface (a secant)
  // has a smaller median than the tangent plane.
  // Nor where a plane explains the whole neighbourhood: there is no edge in it.
  const bool edge = !smooth && chosen + 1 < static_cast<int>(scales.size());
  const int seeds = edge ? std::min(count, kSeedNeighbours + 1) : 0;
  for (int i = 0; i < seeds; ++i) {
    for (int j = i + 1; j < seeds; ++j) {
      const Eigen::Vector3d n = x.col(i).cross(x.col(j));
      const double size = x.col(i).norm() * x.col(j).norm();
      if (!(n.norm() > 1e-9 * size)) continue;  // the query itself, a duplicate, or collinear
      const Plane through{n.normalized(), Eigen::Vector3d::Zero()};
      const double median = medianResidualBelow(
          x, scored, through, std::min(best_median, kThroughQuery * nested_median), residuals,
          smaller);
      if (median < best_median && median < kThroughQuery * nested_median) {
        best_median = median;
        plane = through;
      }
    }
  }
  if (!std::isfinite(best_median)) return result;

  // 4. Noise scale and band, then the least-squares plane of the scale's neighbours within the
  //    band, until it settles. The same points within the band as the last plane's give the same
  //    sums, so the same plane again: it has settled (and its inliers are counted).
  result.noise = std::max(kMadToSigma * best_median, floor);
  const double band = kBand * result.noise;
  result.surface_variation = std::numeric_limits<double>::quiet_NaN();
  int inliers = -1;
  was_inside.clear();
  for (int iteration = 0; iteration < kMaxRefinements; ++iteration) {
    const PointMoments m = within(x, used, plane, band, inside);
    if (inside == was_inside) {
      inliers = m.count();
      break;
    }
    std::swap(inside, was_inside);
    if (m.count() < 3) break;
    const Eigen::Matrix3d covariance = m.covariance();
    const PlaneNormal fit = fitPlaneNormal(covariance);
    if (!fit.valid) break;
    const Plane next_plane{fit.normal.dot(plane.normal) < 0.0 ? -fit.normal : fit.normal,
                           m.centroid()};
    const bool converged = (next_plane.normal - plane.normal).norm() < kConverged;
    plane = next_plane;
    result.surface_variation = fit.surface_variation;
    result.residual =
        fit.surface_variation * covariance.trace() * m.count() / std::max(m.count() - 3, 1);
    if (converged) break;
  }
  if (std::isnan(result.surface_variation)) {  // no refit: the chosen plane's own spread
    PointMoments all;
    for (int i = 0; i < used; ++i) all.add(x.col(i));
    const PlaneFit fit = fitPlane(all.centroid(), all.covariance());
    result.surface_variation = fit.surface_variation;
    result.residual = fit.eigenvalues[0] * all.count() / std::max(all.count() - 3, 1);
  }
  if (inliers < 0) inliers = countWithin(x, used, plane, band);
  result.normal = plane.normal;
  result.centroid = plane.centroid;
  result.scale = inliers;
  result.confidence = static_cast<double>(inliers) / count;
  result.valid = result.normal.allFinite() && std::isfinite(result.surface_variation);
  return result;
}

}  // namespace pcl_ddg
