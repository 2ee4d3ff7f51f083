#include "server/worker_pool.h"

#include <algorithm>

namespace svrc::server {

WorkerPool::WorkerPool(int num_workers, JobQueue* queue, RunFn run)
    : queue_(queue), run_(std::move(run)) {
  threads_.reserve(std::max(1, num_workers));
  for (int i = 0; i < std::max(1, num_workers); ++i) threads_.emplace_back([this] { Loop(); });
}

WorkerPool::~WorkerPool() { Join(); }

void WorkerPool::Join() {
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
}

void WorkerPool::Loop() {
  while (std::optional<std::string> id = queue_->Pop()) {
    busy_.fetch_add(1);
    run_(*id);
    busy_.fetch_sub(1);
  }
}

}  // namespace svrc::server
