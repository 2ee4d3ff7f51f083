#include "server/job_queue.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace svrc::server {

absl::Status InMemoryJobQueue::Push(const std::string& job_id) {
  absl::MutexLock lock(&mu_);
  if (closed_) return absl::UnavailableError("job queue closed: server shutting down");
  if (ids_.size() >= capacity_) {
    return absl::ResourceExhaustedError(
        absl::StrCat("job queue full (", capacity_, " queued jobs); retry later"));
  }
  ids_.push_back(job_id);
  return absl::OkStatus();
}

std::optional<std::string> InMemoryJobQueue::Pop() {
  absl::MutexLock lock(&mu_);
  mu_.Await(absl::Condition(
      +[](InMemoryJobQueue* q) ABSL_NO_THREAD_SAFETY_ANALYSIS { return q->closed_ || !q->ids_.empty(); },
      this));
  if (closed_) return std::nullopt;
  std::string id = std::move(ids_.front());
  ids_.pop_front();
  return id;
}

bool InMemoryJobQueue::Remove(const std::string& job_id) {
  absl::MutexLock lock(&mu_);
  auto it = std::find(ids_.begin(), ids_.end(), job_id);
  if (it == ids_.end()) return false;
  ids_.erase(it);
  return true;
}

size_t InMemoryJobQueue::Size() const {
  absl::MutexLock lock(&mu_);
  return ids_.size();
}

std::vector<std::string> InMemoryJobQueue::Close() {
  absl::MutexLock lock(&mu_);
  closed_ = true;
  std::vector<std::string> rest(ids_.begin(), ids_.end());
  ids_.clear();
  return rest;
}

}  // namespace svrc::server
