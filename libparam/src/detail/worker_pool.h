// A fixed set of worker threads for data-parallel loops that run many times in a row (the
// optimizer's rounds: thousands per map, each a few milliseconds). Internal to libparam.
//
// Why not an OpenMP parallel region per round: GNU OpenMP keeps idle team threads spinning
// between regions, which on a loaded machine burns a core per thread for nothing (the CPU
// time with two threads was 1.1-2x that of one) and delays the threads that have work. Here
// idle workers block on a condition variable, the calling thread takes part in every loop,
// and items are handed out in chunks from per-thread segments of the range (run_chunks).
// Results must not depend on which thread runs an item (the callers write only to the item's
// own slot).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace spherekit::detail {

class WorkerPool {
 public:
  /// `threads` in total including the caller (<= 1: no extra threads, loops run inline).
  explicit WorkerPool(int threads) : cursors_(static_cast<size_t>(std::max(1, threads))) {
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { worker(i); });
  }
  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    start_cv_.notify_all();
    for (auto& t : workers_) t.join();
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  /// Calls body(i, thread) for every i in [0, n), thread in [0, threads()); chunks of
  /// `chunk` items. Serial when n is small or there are no workers: waking threads costs
  /// more than it saves below a few hundred cheap items.
  ///
  /// `side`, if given, is serial work of the caller's that touches nothing the body reads or
  /// writes: the calling thread runs it once the loop is open, while the workers start on
  /// the items, and then joins them (it is run exactly once, also when the loop is serial).
  void parallel_for(int n, int chunk, int min_parallel, const std::function<void(int, int)>& body,
                    const std::function<void()>& side = {}) {
    if (n <= 0) {
      if (side) side();
      return;
    }
    if (workers_.empty() || n < min_parallel) {
      if (side) side();
      for (int i = 0; i < n; ++i) body(i, 0);
      return;
    }
    bool wake = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      body_ = &body;
      chunk_ = std::max(1, chunk);
      const int segments = static_cast<int>(cursors_.size());
      for (int k = 0; k < segments; ++k) {
        cursors_[static_cast<size_t>(k)].next.store(static_cast<int>(static_cast<long long>(n) * k / segments));
        cursors_[static_cast<size_t>(k)].end = static_cast<int>(static_cast<long long>(n) * (k + 1) / segments);
      }
      open_ = true;
      joined_ = 0;
      generation_.fetch_add(1, std::memory_order_release);
      wake = sleeping_ > 0;
    }
    if (wake) start_cv_.notify_all();
    if (side) side();
    run_chunks(0);
    // Wait only for the workers that joined while the loop was open: they are running
    // chunks now. One still waking up (tens of microseconds on a virtual machine, longer
    // than many of the optimizer's loops) finds the loop closed and goes back to sleep, so
    // its wake-up is never on the caller's path.
    {
      std::lock_guard<std::mutex> lock(mutex_);
      open_ = false;
    }
    // The joined workers are on their last chunks: watch for them briefly before sleeping.
    const auto watch_end = std::chrono::steady_clock::now() + kWatch;
    while (joined_.load(std::memory_order_acquire) > 0 && std::chrono::steady_clock::now() < watch_end)
      std::this_thread::yield();
    std::unique_lock<std::mutex> lock(mutex_);
    done_cv_.wait(lock, [&] { return joined_.load() == 0; });
    body_ = nullptr;
  }

 private:
  // Each thread drains its own contiguous segment first, then helps with the others'. The
  // optimizer's loops run over vertex ids in ascending order, class after class, so a thread
  // keeps working on the same part of the mesh from one loop to the next, and the positions
  // it reads are mostly the ones it wrote itself (still in its core's cache). With one shared
  // counter every chunk went to either thread: the vertex work itself cost 28% more CPU with
  // two threads than with one (bunny), most of it in reading the ring's positions.
  void run_chunks(int thread) {
    const std::function<void(int, int)>& body = *body_;
    const int segments = static_cast<int>(cursors_.size());
    for (int k = 0; k < segments; ++k) {
      Cursor& cursor = cursors_[static_cast<size_t>((thread + k) % segments)];
      for (;;) {
        const int begin = cursor.next.fetch_add(chunk_);
        if (begin >= cursor.end) break;
        const int end = std::min(cursor.end, begin + chunk_);
        for (int i = begin; i < end; ++i) body(i, thread);
      }
    }
  }

  void worker(int thread) {
    unsigned long seen = 0;
    for (;;) {
      // The optimizer's loops come in bursts (a round's colour classes, a few microseconds of
      // serial work apart): a worker that has just finished one watches for the next for a
      // short while before it sleeps, so it joins at once instead of after a wake-up. The
      // watch is bounded (kWatch), so an idle pool costs no CPU.
      const auto watch_end = std::chrono::steady_clock::now() + kWatch;
      while (generation_.load(std::memory_order_acquire) == seen && std::chrono::steady_clock::now() < watch_end)
        std::this_thread::yield();
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ++sleeping_;
        start_cv_.wait(lock, [&] { return stop_ || generation_.load() != seen; });
        --sleeping_;
        if (stop_) return;
        seen = generation_.load();
        if (!open_) continue;  // the caller has finished this loop without us
        ++joined_;
      }
      run_chunks(thread);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        --joined_;
      }
      done_cv_.notify_one();
    }
  }

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_cv_, done_cv_;
  const std::function<void(int, int)>* body_ = nullptr;
  int chunk_ = 1;
  std::atomic<int> joined_{0};  // workers running the current loop (changed under mutex_)
  // One cursor per thread's segment (threads() of them), each on its own cache line.
  struct alignas(64) Cursor {
    std::atomic<int> next{0};
    int end = 0;
  };
  std::vector<Cursor> cursors_;
  std::atomic<unsigned long> generation_{0};  // written under mutex_, watched without it
  int sleeping_ = 0;                           // workers waiting on start_cv_
  static constexpr std::chrono::microseconds kWatch{50};
  bool stop_ = false, open_ = false;
};

}  // namespace spherekit::detail
