// Where finished meshes (encoded containers) live until fetched and deleted.
// An interface so that an object store or a shared volume is a new
// implementation (DESIGN.md "Deployment and scale"); DiskResultStore keeps
// them under DATA_DIR/results with atomic writes, a retention time and a quota.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"

namespace svrc::server {

struct StoredResult {
  uint64_t size = 0;
  std::string sha256;  // hex
  absl::Time created;
};

class ResultStore {
 public:
  virtual ~ResultStore() = default;
  // Stores `bytes` under `key` ([A-Za-z0-9_-]+), replacing nothing: a key is
  // written once. RESOURCE_EXHAUSTED when the quota would be exceeded.
  virtual absl::StatusOr<StoredResult> Put(const std::string& key, std::string_view bytes) = 0;
  // NOT_FOUND when absent.
  virtual absl::StatusOr<StoredResult> Stat(const std::string& key) = 0;
  // Up to `max_bytes` from `offset`; OUT_OF_RANGE when offset > size.
  virtual absl::StatusOr<std::string> Read(const std::string& key, uint64_t offset,
                                           uint64_t max_bytes) = 0;
  // OK when absent too.
  virtual absl::Status Delete(const std::string& key) = 0;
  // Deletes everything created before `cutoff`; returns the keys removed.
  virtual std::vector<std::string> RemoveOlderThan(absl::Time cutoff) = 0;
  virtual uint64_t UsedBytes() = 0;
};

class DiskResultStore final : public ResultStore {
 public:
  // Creates DIR/results if needed, drops half-written files and indexes the
  // results already there (they count against the quota and expire by age).
  static absl::StatusOr<std::unique_ptr<DiskResultStore>> Open(const std::string& data_dir,
                                                               uint64_t quota_bytes);

  absl::StatusOr<StoredResult> Put(const std::string& key, std::string_view bytes) override;
  absl::StatusOr<StoredResult> Stat(const std::string& key) override;
  absl::StatusOr<std::string> Read(const std::string& key, uint64_t offset,
                                   uint64_t max_bytes) override;
  absl::Status Delete(const std::string& key) override;
  std::vector<std::string> RemoveOlderThan(absl::Time cutoff) override;
  uint64_t UsedBytes() override;

  const std::string& dir() const { return dir_; }

 private:
  DiskResultStore(std::string dir, uint64_t quota) : dir_(std::move(dir)), quota_(quota) {}
  std::string DataPath(const std::string& key) const;
  std::string MetaPath(const std::string& key) const;
  void RemoveFiles(const std::string& key);

  const std::string dir_;
  const uint64_t quota_;
  // std::mutex (intercepted by TSan, unlike Debian's absl::Mutex). Guards
  // every field below; file I/O of Put runs outside it.
  std::mutex mu_;
  std::map<std::string, StoredResult> index_;
  uint64_t used_ = 0;
  uint64_t reserved_ = 0;  // bytes of Puts in flight
  uint64_t tmp_counter_ = 0;
};

}  // namespace svrc::server
