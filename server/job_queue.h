// The queue between the service and the workers: job ids, bounded, FIFO.
// An interface so that a shared queue (e.g. Redis streams, DESIGN.md
// "Deployment and scale") is a new implementation, not a rewrite.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"

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
  // std::mutex, not absl::Mutex: TSan intercepts pthread mutexes, while
  // Debian's Abseil is not TSan-built (docs/service.md "TSan").
  mutable std::mutex mu_;
  // Signalled when ids_ gains an id (one waiter) or the queue closes (all).
  std::condition_variable not_empty_or_closed_;
  std::deque<std::string> ids_;  // guarded by mu_
  bool closed_ = false;           // guarded by mu_
};

}  // namespace svrc::server
