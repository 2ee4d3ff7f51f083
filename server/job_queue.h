// The queue between the service and the workers: job ids, bounded, FIFO.
// An interface so that a shared queue (e.g. Redis streams, DESIGN.md
// "Deployment and scale") is a new implementation, not a rewrite.
#pragma once

#include <cstddef>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"

namespace svrc::server {

class JobQueue {
 public:
  virtual ~JobQueue() = default;
  // RESOURCE_EXHAUSTED when full, UNAVAILABLE after Close().
  virtual absl::Status Push(const std::string& job_id) = 0;
  // Blocks until an id is available; nullopt once the queue is closed.
  virtual std::optional<std::string> Pop() = 0;
  // Takes a still-queued id out (a cancelled or expired job); false if absent.
  virtual bool Remove(const std::string& job_id) = 0;
  virtual size_t Size() const = 0;
  virtual size_t Capacity() const = 0;
  // Refuses further pushes, wakes every Pop() (they return nullopt) and
  // returns the ids still queued, in order.
  virtual std::vector<std::string> Close() = 0;
};

class InMemoryJobQueue final : public JobQueue {
 public:
  explicit InMemoryJobQueue(size_t capacity) : capacity_(capacity) {}

  absl::Status Push(const std::string& job_id) override;
  std::optional<std::string> Pop() override;
  bool Remove(const std::string& job_id) override;
  size_t Size() const override;
  size_t Capacity() const override { return capacity_; }
  std::vector<std::string> Close() override;

 private:
  const size_t capacity_;
  mutable absl::Mutex mu_;
  std::deque<std::string> ids_ ABSL_GUARDED_BY(mu_);
  bool closed_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace svrc::server
