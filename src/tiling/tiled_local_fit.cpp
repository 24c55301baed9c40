#include "pcl_ddg/tiling/tiled_local_fit.h"

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <numeric>
#include <utility>

#include "pcl_ddg/features/robust_normal_estimation.h"
#include "pcl_ddg/features/widening_planes.h"
#include "pcl_ddg/search/kd_tree_search.h"
#include "pcl_ddg/tiling/tile_certificate.h"

namespace pcl_ddg {
namespace {

Eigen::Vector3d position(const pcl::PointXYZ& p) {
  return p.getVector3fMap().cast<double>();
}

Eigen::AlignedBox3d grown(const Eigen::AlignedBox3d& box, double by) {
  return {box.min().array() - by, box.max().array() + by};
}

// For k nearest: how far each own point looks (tile_certificate.h), before its fit, to choose the
// halo.
std::vector<double> lookingDistances(const TilePoints& tile, int k) {
  KdTreeSearch<pcl::PointXYZ> search;
  search.setInputCloud(tile.points);
  std::vector<double> distance(tile.own->size());
#pragma omp parallel
  {
    pcl::Indices neighbours;
    std::vector<float> squared_distances;
#pragma omp for schedule(static)
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(tile.own->size()); ++i) {
      const pcl::PointXYZ& q = (*tile.points)[(*tile.own)[i]];
      const int found = search.nearestKSearch(q, k, neighbours, squared_distances);
      distance[i] = lookingDistance(found < k ? std::numeric_limits<float>::infinity()
                                              : squared_distances.back());
    }
  }
  return distance;
}

// How far each own point of a robust fit looked (tile_certificate.h): its own k nearest, and the
// rows its wider planes read (RobustNormalEstimation::getReaches).
struct LookedFit {
  LocalFitResult fit;
  std::vector<double> looked;
};

LookedFit fitLooking(const TilePoints& points, LocalFitOptions options) {
  auto search = std::make_shared<LookingKdTree>(points.points->size(), options.k);
  options.kd_tree_search = search;
  options.report_reaches = true;
  LocalCloud cloud(points.points);
  cloud.positions = points.positions;
  cloud.origin = points.origin;
  LookedFit out;
  out.fit = fitLocalSurfaces(cloud, nullptr, options, points.own);
  out.looked.resize(points.own->size());
  for (std::size_t j = 0; j < out.looked.size(); ++j)
    out.looked[j] = lookingDistance(search->squaredKth((*points.own)[j]), out.fit.reaches[j]);
  return out;
}

// A robust fit of a tile's own points in parts of at most `most` gathered points each where the
// tile gathered more (its halo, a dozen rows' radii, can hold several times its points): the own
// points halved in the middle of their box's longest side until each part's box grown by the halo
// holds at most `most` of the gathered points, or until halving would leave a half over the limit
// with more than 3/4 of the part's (a side less than twice the halo, which halving hardly shrinks).
// A part is fitted with the gathered points in its grown box, clipped to the tile's halo box: all
// the cloud's there; reach[j] is how far own point j may look from there (haloReach). One part:
// the tile's own fit, in its halo box. The tile's gathered points stay held meanwhile (at 40 bytes
// or so a point, a tenth of a fit's).
LookedFit fitLookingInParts(const TilePoints& points, const Eigen::AlignedBox3d& halo_box,
                            double halo, const Eigen::AlignedBox3d& bounds, std::int64_t most,
                            const LocalFitOptions& options, std::vector<double>& reach,
                            const std::function<void(const TilePoints&)>& gathered) {
  const auto at = [&](int index) { return position((*points.points)[index]); };
  const auto own_at = [&](int j) { return at((*points.own)[j]); };
  struct Part {
    std::vector<int> slots;    ///< its own points, as indices into points.own
    std::vector<int> members;  ///< the gathered points in its region, ascending positions
    Eigen::AlignedBox3d region;
  };
  Part whole;
  whole.slots.resize(points.own->size());
  std::iota(whole.slots.begin(), whole.slots.end(), 0);
  whole.members.resize(points.points->size());
  std::iota(whole.members.begin(), whole.members.end(), 0);
  whole.region = halo_box;
  std::vector<Part> parts, pending;
  pending.push_back(std::move(whole));
  while (!pending.empty()) {
    Part part = std::move(pending.back());
    pending.pop_back();
    if (static_cast<std::int64_t>(part.members.size()) <= most || part.slots.size() < 2) {
      parts.push_back(std::move(part));
      continue;
    }
    Eigen::AlignedBox3d own_box;
    for (const int j : part.slots) own_box.extend(own_at(j));
    Eigen::Index axis = 0;
    own_box.sizes().maxCoeff(&axis);
    if (!(own_box.sizes()[axis] > 0.0)) {  // all in one place
      parts.push_back(std::move(part));
      continue;
    }
    // Halved in the middle of the box, not at the median point: what a part holds is mostly its
    // halo's points, which follow its box's size, not how many points of its own it has.
    const double cut = own_box.center()[axis];
    const auto middle = std::partition(part.slots.begin(), part.slots.end(),
                                       [&](int j) { return own_at(j)[axis] < cut; });
    Part halves[2];
    for (int h = 0; h < 2; ++h) {
      halves[h].slots.assign(h == 0 ? part.slots.begin() : middle,
                             h == 0 ? middle : part.slots.end());
      Eigen::AlignedBox3d box;
      for (const int j : halves[h].slots) box.extend(own_at(j));
      halves[h].region = grown(box, halo).intersection(part.region);  // within what was gathered
      // The points in the region, and its own points wherever they lie (one a rounding outside
      // its tile's box would be outside; its look past the region then sends it to be fitted
      // apart).
      std::vector<int> own;
      for (const int j : halves[h].slots) own.push_back((*points.own)[j]);
      std::sort(own.begin(), own.end());
      std::vector<int> inside;
      for (const int m : part.members)
        if (halves[h].region.contains(at(m))) inside.push_back(m);
      std::set_union(inside.begin(), inside.end(), own.begin(), own.end(),
                     std::back_inserter(halves[h].members));
    }
    if (halves[0].slots.empty() || halves[1].slots.empty()) {  // nothing on one side of the cut
      parts.push_back(std::move(part));
      continue;
    }
    // Halves over the limit that still hold more than 3/4 of the part's points (a side less than
    // twice the halo, which halving hardly shrinks) would only add work.
    const std::size_t larger = std::max(halves[0].members.size(), halves[1].members.size());
    if (static_cast<std::int64_t>(larger) > most && 4 * larger > 3 * part.members.size()) {
      parts.push_back(std::move(part));
      continue;
    }
    for (Part& half : halves) pending.push_back(std::move(half));
  }
  reach.resize(points.own->size());
  if (parts.size() == 1) {
    gathered(points);
    for (std::size_t j = 0; j < reach.size(); ++j)
      reach[j] = haloReach(own_at(static_cast<int>(j)), halo_box, bounds);
    return fitLooking(points, options);
  }
  LookedFit all;
  all.looked.resize(points.own->size());
  all.fit.normals.resize(points.own->size());
  all.fit.scales.resize(points.own->size());
  all.fit.confidences.resize(points.own->size());
  for (const Part& part : parts) {
    TilePoints fitted;
    fitted.points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    fitted.points->reserve(part.members.size());
    fitted.origin = points.origin;
    if (points.positions)
      fitted.positions = std::make_shared<Eigen::Matrix3Xd>(3, part.members.size());
    for (const int m : part.members) {
      if (points.positions)
        fitted.positions->col(static_cast<Eigen::Index>(fitted.points->size())) =
            points.positions->col(m);
      fitted.points->push_back((*points.points)[m]);
      fitted.global_index.push_back(points.global_index[m]);
    }
    fitted.own = std::make_shared<pcl::Indices>();
    for (const int j : part.slots)
      fitted.own->push_back(static_cast<pcl::index_t>(
          std::lower_bound(part.members.begin(), part.members.end(), (*points.own)[j]) -
          part.members.begin()));
    gathered(fitted);
    const LookedFit looked = fitLooking(fitted, options);
    for (std::size_t i = 0; i < part.slots.size(); ++i) {
      const int j = part.slots[i];
      all.looked[j] = looked.looked[i];
      all.fit.normals[j] = looked.fit.normals[i];
      all.fit.scales[j] = looked.fit.scales[i];
      all.fit.confidences[j] = looked.fit.confidences[i];
      reach[j] = haloReach(own_at(j), part.region, bounds);
    }
  }
  return all;
}

// The points and fits of the own points j with keep[j] only.
void keepOnly(TilePoints& points, LocalFitResult& fit, const std::vector<char>& keep) {
  auto own = std::make_shared<pcl::Indices>();
  LocalFitResult kept;
  kept.normals.is_dense = true;
  for (std::size_t j = 0; j < keep.size(); ++j) {
    if (!keep[j]) continue;
    own->push_back((*points.own)[j]);
    kept.normals.push_back(fit.normals[j]);
    kept.scales.push_back(fit.scales[j]);
    kept.confidences.push_back(fit.confidences[j]);
    if (std::isfinite(fit.normals[j].normal_x)) continue;
    ++kept.failed_points;
    kept.normals.is_dense = false;
  }
  points.own = own;
  fit = std::move(kept);
}

// The 99th percentile of values (not empty): the look that more than 1 % of the points exceed.
double percentile99(std::vector<double> values) {
  const std::size_t p99 = values.size() - 1 - values.size() / 100;
  std::nth_element(values.begin(), values.begin() + p99, values.end());
  return values[p99];
}

// The positions in `points` of the given global indices (all present: gathered in order).
pcl::IndicesPtr positionsOf(const TilePoints& points, const std::vector<std::int64_t>& wanted) {
  auto positions = std::make_shared<pcl::Indices>();
  for (const std::int64_t g : wanted) {
    const auto it = std::lower_bound(points.global_index.begin(), points.global_index.end(), g);
    positions->push_back(static_cast<pcl::index_t>(it - points.global_index.begin()));
  }
  return positions;
}

}  // namespace

void fitTiles(const TilePlan& plan, const LocalFitOptions& options, const PointGatherer& gather,
              const FitConsumer& consume, TilingReport* report) {
  if (options.neighbourhood != NeighbourhoodKind::KdTree)
    throw pcl::BadArgumentException("tiles are fitted with kd-tree neighbourhoods only");
  const Eigen::AlignedBox3d& bounds = plan.histogram.bounds();
  TilingReport local;
  const auto gathered = [&](const TilePoints& points) {
    local.largest_gather = std::max<std::int64_t>(local.largest_gather,
                                                  static_cast<std::int64_t>(points.points->size()));
  };
  const auto fit = [&](TilePoints& points) {
    gathered(points);
    if (points.own->empty()) return;
    LocalCloud cloud(points.points);
    cloud.positions = points.positions;
    cloud.origin = points.origin;
    consume(points, fitLocalSurfaces(cloud, nullptr, options, points.own));
  };
  // Robust with k nearest: how far a point looked is known after its fit (fitLooking). Its fits
  // hold at most as many points as the largest tile owns (what the plan was cut for), where the
  // halo allows it (fitLookingInParts).
  const bool robust = options.method == LocalFitMethod::Robust && options.radius == 0.0;
  std::int64_t most = 0;
  for (const Tile& tile : plan.tiles) most = std::max(most, tile.points);
  LocalFitOptions robust_options = options;
  for (const std::int64_t count : plan.histogram.counts()) robust_options.cloud_points += count;
  struct FarPoint {
    std::int64_t index;  ///< in the cloud
    Eigen::Vector3d at;
    double look;
  };
  // What a far point looks at (the whole cloud when its look is not finite).
  const auto lookBox = [&](const FarPoint& f) {
    return std::isfinite(f.look) ? grown(Eigen::AlignedBox3d(f.at, f.at), f.look) : bounds;
  };
  // Fits far points with what lies in a box about them, a group of near ones at a time (one box
  // for all would gather much of the cloud), again in a wider box for those that look past it
  // (each round at least doubles a look; the cloud's bounds certify every point).
  const auto fitRobustApart = [&](std::vector<FarPoint> far) {
    local.far_points += static_cast<std::int64_t>(far.size());
    while (!far.empty()) {
      // The group: the points within the first one's look of it.
      const Eigen::AlignedBox3d seed = lookBox(far.front());
      std::vector<FarPoint> group, rest;
      Eigen::AlignedBox3d region;
      for (const FarPoint& f : far) {
        if (!seed.contains(f.at)) {
          rest.push_back(f);
          continue;
        }
        group.push_back(f);
        region.extend(lookBox(f));
      }
      region = region.intersection(grown(bounds, 1.0));
      std::vector<std::int64_t> wanted;
      for (const FarPoint& f : group) wanted.push_back(f.index);
      std::sort(wanted.begin(), wanted.end());
      std::sort(group.begin(), group.end(),
                [](const FarPoint& a, const FarPoint& b) { return a.index < b.index; });
      TilePoints points = gather(-1, region);
      points.own = positionsOf(points, wanted);
      gathered(points);
      LookedFit looked = fitLooking(points, robust_options);
      std::vector<char> keep(group.size());
      for (std::size_t j = 0; j < group.size(); ++j) {
        keep[j] = looked.looked[j] <= haloReach(group[j].at, region, bounds);
        if (!keep[j])
          rest.push_back(
              {group[j].index, group[j].at, std::max(looked.looked[j], 2.0 * group[j].look)});
      }
      keepOnly(points, looked.fit, keep);
      if (!points.own->empty()) consume(points, looked.fit);
      far = std::move(rest);
    }
  };
  // k nearest: the halo the tile before needed (neighbouring tiles have alike densities).
  double guess = 0.0;
  for (int t = 0; t < static_cast<int>(plan.tiles.size()); ++t) {
    const Eigen::AlignedBox3d& box = plan.tiles[t].box;
    double halo = options.radius > 0.0 ? radiusHalo(options.radius) : guess;
    TilePoints points = gather(t, grown(box, halo));
    if (options.radius > 0.0) {
      local.widest_halo = std::max(local.widest_halo, halo);
      fit(points);
      continue;
    }
    if (robust && t == 0 && options.k >= kWideGraphWidth) {
      // A first guess: the widest planes read rows up to kWideLevels steps away.
      const std::vector<double> rows = lookingDistances(points, kWideGraphWidth);
      const double widest = percentile99(rows);
      if (std::isfinite(widest)) {
        halo = (kWideLevels + 1) * widest;
        points = gather(t, grown(box, halo));
      }
    }
    for (int round = 0;; ++round) {
      const Eigen::AlignedBox3d halo_box = grown(box, halo);
      LookedFit looked;
      std::vector<double>& looking = looked.looked;
      std::vector<double> reach;  // how far each own point may look from what it was fitted with
      if (robust) {
        if (points.own->empty()) break;
        looked = fitLookingInParts(points, halo_box, halo, bounds, most, robust_options, reach,
                                   gathered);
      } else {
        looking = lookingDistances(points, options.k);
        for (const pcl::index_t at : *points.own)
          reach.push_back(haloReach(position((*points.points)[at]), halo_box, bounds));
      }
      // The halo each point needs (its look beyond what the current halo gives it).
      std::vector<double> needed(looking.size());
      for (std::size_t i = 0; i < looking.size(); ++i)
        needed[i] = std::max(0.0, halo + looking[i] - reach[i]);
      const double p99 = needed.empty() ? 0.0 : percentile99(needed);
      guess = std::isfinite(p99) ? p99 : halo;
      if (p99 > halo && round < 2) {
        // More than 1% look beyond: the halo itself is too narrow. (Robust fits are costly: those
        // this halo certified are kept, the rest fitted again.)
        std::vector<std::int64_t> rest;
        if (robust) {
          std::vector<char> keep(needed.size());
          for (std::size_t i = 0; i < needed.size(); ++i) {
            keep[i] = needed[i] <= halo;
            if (!keep[i]) rest.push_back(points.global_index[(*points.own)[i]]);
          }
          keepOnly(points, looked.fit, keep);
          if (!points.own->empty()) consume(points, looked.fit);
        }
        halo = std::isfinite(p99) ? 1.05 * p99 : 2.0 * halo + box.sizes().norm();
        points = gather(t, grown(box, halo));
        if (robust) points.own = positionsOf(points, rest);
        ++local.halo_growths;
        continue;
      }
      local.widest_halo = std::max(local.widest_halo, halo);
      // The points that look beyond the halo are fitted apart, with what lies around them.
      std::vector<FarPoint> far;
      std::vector<char> keep(needed.size());
      for (std::size_t i = 0; i < needed.size(); ++i) {
        const pcl::index_t at = (*points.own)[i];
        keep[i] = needed[i] <= halo;
        if (!keep[i])
          far.push_back({points.global_index[at], position((*points.points)[at]), looking[i]});
      }
      if (robust) {
        keepOnly(points, looked.fit, keep);
        if (!points.own->empty()) consume(points, looked.fit);
        fitRobustApart(std::move(far));
        break;
      }
      auto inside = std::make_shared<pcl::Indices>();
      for (std::size_t i = 0; i < keep.size(); ++i)
        if (keep[i]) inside->push_back((*points.own)[i]);
      points.own = inside;
      fit(points);
      if (!far.empty()) {
        Eigen::AlignedBox3d around;
        for (const FarPoint& f : far) around.extend(lookBox(f));
        TilePoints far_points = gather(-1, around.intersection(grown(bounds, 1.0)));
        std::vector<std::int64_t> wanted;
        for (const FarPoint& f : far) wanted.push_back(f.index);
        far_points.own = positionsOf(far_points, wanted);
        local.far_points += static_cast<std::int64_t>(far.size());
        fit(far_points);
      }
      break;
    }
  }
  local.tiles = plan.tiles.size();
  if (report) *report = local;
}

LocalFitResult fitLocalSurfacesTiled(const LocalCloud& local, const LocalFitOptions& options,
                                     const TilingOptions& tiling, TilingReport* report) {
  const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud = local.points;
  if (!cloud || cloud->empty()) throw pcl::BadArgumentException("the cloud is empty");
  const std::size_t n = cloud->size();
  Eigen::AlignedBox3d bounds;
  for (const auto& p : *cloud)
    if (pcl::isXYZFinite(p)) bounds.extend(position(p));

  LocalFitResult result;
  pcl::Normal invalid;
  invalid.normal_x = invalid.normal_y = invalid.normal_z = invalid.curvature =
      std::numeric_limits<float>::quiet_NaN();
  result.normals.assign(n, invalid);
  result.normals.width = cloud->width;  // an organized cloud stays organized, as in PCL
  result.normals.height = cloud->height;
  if (options.method == LocalFitMethod::Quadric) {
    pcl::PrincipalCurvatures none;
    none.principal_curvature_x = none.principal_curvature_y = none.principal_curvature_z =
        none.pc1 = none.pc2 = std::numeric_limits<float>::quiet_NaN();
    result.curvatures.assign(n, none);
  }
  if (options.method == LocalFitMethod::Robust) {
    result.scales.assign(n, std::numeric_limits<float>::quiet_NaN());
    result.confidences.assign(n, std::numeric_limits<float>::quiet_NaN());
  }
  result.normals.is_dense = true;
  for (const auto& p : *cloud) {
    if (pcl::isXYZFinite(p)) continue;
    ++result.failed_points;  // as the estimator counts them
    result.normals.is_dense = false;
  }
  if (bounds.isEmpty()) return result;

  PointHistogram histogram(bounds, tiling.resolution);
  std::vector<int> cell(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (!pcl::isXYZFinite((*cloud)[i])) continue;
    cell[i] = histogram.cellOf(position((*cloud)[i]));
    histogram.add(position((*cloud)[i]));
  }
  const TilePlan plan = planTiles(histogram, tiling.max_points_per_tile);

  const auto gather = [&](int tile, const Eigen::AlignedBox3d& region) {
    TilePoints points;
    points.points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    points.own = std::make_shared<pcl::Indices>();
    points.origin = local.origin;
    for (std::size_t i = 0; i < n; ++i) {
      if (cell[i] < 0) continue;
      const bool own = tile >= 0 && plan.tile_of_cell[cell[i]] == tile;
      if (!own && !region.contains(position((*cloud)[i]))) continue;
      if (own) points.own->push_back(static_cast<pcl::index_t>(points.points->size()));
      points.points->push_back((*cloud)[i]);
      points.global_index.push_back(static_cast<std::int64_t>(i));
    }
    if (local.positions) {
      points.positions = std::make_shared<Eigen::Matrix3Xd>(3, points.global_index.size());
      for (std::size_t j = 0; j < points.global_index.size(); ++j)
        points.positions->col(static_cast<Eigen::Index>(j)) =
            local.positions->col(points.global_index[j]);
    }
    return points;
  };
  const auto consume = [&](const TilePoints& points, const LocalFitResult& fit) {
    for (std::size_t j = 0; j < points.own->size(); ++j) {
      const std::int64_t i = points.global_index[(*points.own)[j]];
      result.normals[i] = fit.normals[j];
      if (!fit.curvatures.empty()) result.curvatures[i] = fit.curvatures[j];
      if (!fit.scales.empty()) {
        result.scales[i] = fit.scales[j];
        result.confidences[i] = fit.confidences[j];
      }
    }
    result.failed_points += fit.failed_points;
    result.fallback_points += fit.fallback_points;
    if (!fit.normals.is_dense) result.normals.is_dense = false;
  };
  fitTiles(plan, options, gather, consume, report);
  return result;
}

}  // namespace pcl_ddg
