// The job journal: an append-only log of job state changes in
// DATA_DIR/journal/journal.log (length + CRC-32C framed JournalRecord protos)
// and the submitted inputs in DATA_DIR/inputs, so that a restarted server
// (also after kill -9) knows every accepted job. DESIGN.md "Data flow";
// durability policy in docs/service.md "Persistence".
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "svrc/v1/journal.pb.h"
#include "svrc/v1/service.pb.h"

namespace svrc::server {

// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), bitwise table.
uint32_t Crc32c(std::string_view bytes);

class Journal {
 public:
  // Creates DIR/journal and DIR/inputs if needed and reads the log: every
  // record up to the first torn or corrupt one (a crash mid-append), after
  // which the file is truncated.
  static absl::StatusOr<std::unique_ptr<Journal>> Open(const std::string& data_dir);
  ~Journal();

  // The records read by Open, in order (once).
  std::vector<v1::JournalRecord> TakeReplayed();
  // Bytes dropped from the tail at Open (0: the log was clean).
  uint64_t dropped_tail_bytes() const { return dropped_tail_bytes_; }

  // Appends one record; with `sync` it is on disk (fdatasync) when this returns.
  absl::Status Append(const v1::JournalRecord& record, bool sync);
  // Replaces the log by `records` atomically (temp file, fsync, rename,
  // directory fsync): compaction.
  absl::Status Rewrite(const std::vector<v1::JournalRecord>& records);
  // Records appended since Open or the last Rewrite.
  uint64_t appended_since_rewrite() const;

  // The input of a job, stored before its SUBMITTED record (atomic, fsynced).
  absl::Status PutInput(const std::string& job_id, const v1::SubmitJobRequest& request);
  absl::StatusOr<v1::SubmitJobRequest> GetInput(const std::string& job_id);
  void DeleteInput(const std::string& job_id);
  // Job ids with a stored input.
  std::vector<std::string> ListInputs();

 private:
  Journal(std::string journal_dir, std::string inputs_dir)
      : journal_dir_(std::move(journal_dir)), inputs_dir_(std::move(inputs_dir)) {}
  std::string LogPath() const { return journal_dir_ + "/journal.log"; }
  std::string InputPath(const std::string& job_id) const;

  const std::string journal_dir_;
  const std::string inputs_dir_;
  std::vector<v1::JournalRecord> replayed_;
  uint64_t dropped_tail_bytes_ = 0;
  // std::mutex (intercepted by TSan, unlike Debian's absl::Mutex); guards
  // fd_ and appended_.
  mutable std::mutex mu_;
  int fd_ = -1;
  uint64_t appended_ = 0;
};

}  // namespace svrc::server
