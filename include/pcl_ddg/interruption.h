#pragma once
/** \file
 * Interrupting a long computation (Ctrl-C in Python, a cancel button): the caller installs a
 * check for its own thread for the duration of a call (InterruptionScope); the library's long
 * loops run it from that thread about every 0.1 s of work and, once it returns true, every thread
 * of the loop skips the points left and the call throws InterruptedException. Without a scope
 * nothing is checked and the loops cost one relaxed atomic load per point more. The check runs
 * inside OpenMP regions: it must not throw.
 */
#include <pcl/exceptions.h>

#include <atomic>
#include <chrono>
#include <functional>

namespace pcl_ddg {

/** A computation stopped because its InterruptionScope's check returned true. */
class InterruptedException : public pcl::PCLException {
 public:
  InterruptedException() : pcl::PCLException("interrupted") {}
};

/** Installs check for the calling thread's library calls until destroyed (scopes nest). */
class InterruptionScope {
 public:
  explicit InterruptionScope(std::function<bool()> check);
  ~InterruptionScope();
  InterruptionScope(const InterruptionScope&) = delete;
  InterruptionScope& operator=(const InterruptionScope&) = delete;

 private:
  std::function<bool()> check_;
  const std::function<bool()>* enclosing_;
};

namespace detail {

/**
 * A loop's view of the calling thread's check: made on the calling thread before a parallel
 * region, polled by every thread of it per point. Only thread 0 of the region (the caller) runs
 * the check, when about 0.1 s have passed; the clock is read every `stride` points, a stride
 * that adapts so that reading it costs nothing next to the points' work.
 */
class InterruptionPoll {
 public:
  InterruptionPoll();
  /** True once interrupted: skip the point. */
  bool stopped();
  /** After the loop: throws InterruptedException if it was interrupted. */
  void throwIfStopped() const;

 private:
  const std::function<bool()>* check_;
  std::atomic<bool> stopped_{false};
  std::chrono::steady_clock::time_point last_clock_, next_check_;
  long countdown_ = 1, stride_ = 1;
};

}  // namespace detail
}  // namespace pcl_ddg
