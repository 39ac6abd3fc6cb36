// Independent jobs (one per mesh) on a few worker threads, with progress and cancellation
// reported on the calling thread, as the ProgressFn contract requires. Internal to libparam.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::detail {

/// Worker threads for `requested` (0 = hardware concurrency).
inline int resolve_threads(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

/// Runs job(i, threads_per_job, keep_going) for i in [0, count) on up to `threads` workers.
/// Each job gets the thread budget left for it (threads / workers, at least 1) and a
/// keep_going() to poll (false after cancellation). `progress` is called on the calling
/// thread about ten times a second with `stage`, the finished count as level and the
/// fraction done; returning false cancels the jobs not yet finished.
/// A job failing (other than Cancelled) cancels the jobs not yet finished. Returns the
/// failure of the lowest-numbered failed job, else Cancelled, else OK.
inline Status run_parallel_jobs(int count, int threads, const std::string& stage, const ProgressFn& progress,
                                const std::function<Status(int, int, const std::function<bool()>&)>& job) {
  if (count <= 0) return Status();
  const int workers = std::min(count, resolve_threads(threads));
  const int per_job = std::max(1, resolve_threads(threads) / workers);
  std::vector<Status> status(static_cast<size_t>(count));
  std::atomic<int> next{0};
  std::atomic<bool> cancel{false};
  std::mutex mutex;
  std::condition_variable done_cv;
  int finished = 0;
  const std::function<bool()> keep_going = [&cancel] { return !cancel.load(std::memory_order_relaxed); };
  auto work = [&] {
    for (int i; (i = next.fetch_add(1)) < count;) {
      Status s = cancel.load() ? Status(ErrorCode::Cancelled, "cancelled") : job(i, per_job, keep_going);
      if (!s.ok() && s.code() != ErrorCode::Cancelled) cancel = true;  // no point finishing the others
      std::lock_guard<std::mutex> lock(mutex);
      status[static_cast<size_t>(i)] = std::move(s);
      ++finished;
      done_cv.notify_all();
    }
  };
  if (workers == 1) {
    // No thread needed: the job runs on the calling thread, and its polls are heartbeats.
    for (int i = 0; i < count; ++i) {
      const double fraction = static_cast<double>(i) / count;
      const std::function<bool()> poll = [&] {
        if (!cancel.load() && !report_progress(progress, stage, i, fraction)) cancel = true;
        return !cancel.load();
      };
      status[static_cast<size_t>(i)] = poll() ? job(i, per_job, poll) : Status(ErrorCode::Cancelled, "cancelled");
      if (!status[static_cast<size_t>(i)].ok() && status[static_cast<size_t>(i)].code() != ErrorCode::Cancelled)
        cancel = true;
    }
  } else {
    std::vector<std::thread> pool;
    for (int w = 0; w < workers; ++w) pool.emplace_back(work);
    {
      std::unique_lock<std::mutex> lock(mutex);
      while (finished < count) {
        const int f = finished;
        lock.unlock();
        if (!cancel.load() && !report_progress(progress, stage, f, static_cast<double>(f) / count)) cancel = true;
        lock.lock();
        done_cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return finished > f; });
      }
    }
    for (auto& t : pool) t.join();
  }
  report_progress(progress, stage, count, 1.0);
  // A real failure first (the lowest-numbered), then cancellation.
  for (const Status& s : status)
    if (!s.ok() && s.code() != ErrorCode::Cancelled) return s;
  for (const Status& s : status)
    if (!s.ok()) return s;
  return Status();
}

}  // namespace spherekit::detail
