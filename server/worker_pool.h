// N worker threads taking job ids from a JobQueue and running them. A job
// owns its memory; the workers share nothing but the queue (STYLE.md).
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "server/job_queue.h"

namespace svrc::server {

class WorkerPool {
 public:
  using RunFn = std::function<void(const std::string& job_id)>;

  // Starts `num_workers` (>= 1) threads at once. `queue` must outlive the pool.
  WorkerPool(int num_workers, JobQueue* queue, RunFn run);
  // Joins; the queue must have been closed (or be closed by now).
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // Returns once every worker has left (after queue->Close() and the jobs
  // they were running have returned).
  void Join();
  int size() const { return static_cast<int>(threads_.size()); }
  // Workers inside `run` right now.
  int busy() const { return busy_.load(); }

 private:
  void Loop();

  JobQueue* queue_;
  RunFn run_;
  std::atomic<int> busy_{0};
  std::vector<std::thread> threads_;
};

}  // namespace svrc::server
