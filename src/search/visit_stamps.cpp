#include "pcl_ddg/search/visit_stamps.h"

#include <algorithm>

namespace pcl_ddg {
namespace detail {

VisitStamps& VisitStamps::forThisThread(int num_vertices) {
  thread_local VisitStamps stamps;
  if (stamps.stamps_.size() < static_cast<std::size_t>(num_vertices))
    stamps.stamps_.resize(num_vertices, 0);
  return stamps;
}

void VisitStamps::startQuery() {
  if (++current_ == 0) {  // wrapped after 2^32 queries: old stamps could collide
    std::fill(stamps_.begin(), stamps_.end(), 0);
    current_ = 1;
  }
}

}  // namespace detail
}  // namespace pcl_ddg
