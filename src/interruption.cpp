#include "pcl_ddg/interruption.h"

#include <algorithm>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace {

const std::function<bool()>*& installedCheck() {
  thread_local const std::function<bool()>* check = nullptr;
  return check;
}

constexpr auto kCheckInterval = std::chrono::milliseconds(100);

}  // namespace

InterruptionScope::InterruptionScope(std::function<bool()> check)
    : check_(std::move(check)), enclosing_(installedCheck()) {
  installedCheck() = check_ ? &check_ : enclosing_;
}

InterruptionScope::~InterruptionScope() {
  installedCheck() = enclosing_;
}

namespace detail {

InterruptionPoll::InterruptionPoll()
    : check_(installedCheck()),
      last_clock_(std::chrono::steady_clock::now()),
      next_check_(last_clock_ + kCheckInterval) {}

bool InterruptionPoll::stopped() {
  if (stopped_.load(std::memory_order_relaxed)) return true;
  if (check_ == nullptr) return false;
#ifdef _OPENMP
  if (omp_get_thread_num() != 0) return false;
#endif
  if (--countdown_ > 0) return false;
  const auto now = std::chrono::steady_clock::now();
  // Read the clock about every millisecond of work: double the stride while it comes sooner.
  const auto since = now - last_clock_;
  if (since < std::chrono::microseconds(500)) stride_ = std::min(stride_ * 2, 1L << 20);
  if (since > std::chrono::milliseconds(5)) stride_ = std::max(stride_ / 2, 1L);
  countdown_ = stride_;
  last_clock_ = now;
  if (now < next_check_) return false;
  next_check_ = now + kCheckInterval;
  if ((*check_)()) stopped_.store(true, std::memory_order_relaxed);
  return stopped_.load(std::memory_order_relaxed);
}

void InterruptionPoll::throwIfStopped() const {
  if (stopped_.load(std::memory_order_relaxed)) throw InterruptedException();
}

}  // namespace detail
}  // namespace pcl_ddg
