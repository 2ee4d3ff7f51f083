#include "server/job_queue.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace svrc::server {

absl::Status InMemoryJobQueue::Push(const std::string& job_id) {
  {
    std::scoped_lock lock(mu_);
    if (closed_) return absl::UnavailableError("job queue closed: server shutting down");
    if (ids_.size() >= capacity_) {
      return absl::ResourceExhaustedError(
          absl::StrCat("job queue full (", capacity_, " queued jobs); retry later"));
    }
    ids_.push_back(job_id);
  }
  // One new id: one Pop() can proceed. A woken Pop that finds the id gone
  // (Remove won the race) waits again; the next Push wakes the next one.
  not_empty_or_closed_.notify_one();
  return absl::OkStatus();
}

std::optional<std::string> InMemoryJobQueue::Pop() {
  std::unique_lock lock(mu_);
  not_empty_or_closed_.wait(lock, [this] { return closed_ || !ids_.empty(); });
  if (closed_) return std::nullopt;
  std::string id = std::move(ids_.front());
  ids_.pop_front();
  return id;
}

bool InMemoryJobQueue::Remove(const std::string& job_id) {
  std::scoped_lock lock(mu_);
  auto it = std::find(ids_.begin(), ids_.end(), job_id);
  if (it == ids_.end()) return false;
  ids_.erase(it);
  return true;
}

size_t InMemoryJobQueue::Size() const {
  std::scoped_lock lock(mu_);
  return ids_.size();
}

std::vector<std::string> InMemoryJobQueue::Close() {
  std::vector<std::string> rest;
  {
    std::scoped_lock lock(mu_);
    closed_ = true;
    rest.assign(ids_.begin(), ids_.end());
    ids_.clear();
  }
  not_empty_or_closed_.notify_all();  // every blocked Pop() returns nullopt
  return rest;
}

}  // namespace svrc::server
