#include "server/journal.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "absl/strings/str_cat.h"

namespace svrc::server {
namespace fs = std::filesystem;
namespace {

// Record framing: magic, payload length, CRC-32C of the payload (all
// little-endian u32), then the serialized JournalRecord.
constexpr uint32_t kMagic = 0x314a5653;  // "SVJ1"
constexpr size_t kHeader = 12;
constexpr uint32_t kMaxRecord = 64u << 20;

void PutU32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
uint32_t GetU32(const char* p) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(static_cast<unsigned char>(p[i])) << (8 * i);
  return v;
}

absl::Status ErrnoError(const std::string& what, const std::string& path) {
  return absl::InternalError(absl::StrCat(what, " ", path, ": ", std::strerror(errno)));
}

absl::Status WriteAll(int fd, std::string_view bytes, const std::string& path) {
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return ErrnoError("cannot write", path);
    }
    done += static_cast<size_t>(n);
  }
  return absl::OkStatus();
}

void SyncDir(const std::string& dir) {
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

absl::Status WriteFileAtomically(const std::string& path, std::string_view bytes) {
  const std::string tmp = path + ".tmp";
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return ErrnoError("cannot create", tmp);
  absl::Status s = WriteAll(fd, bytes, tmp);
  if (s.ok() && ::fsync(fd) != 0) s = ErrnoError("cannot fsync", tmp);
  ::close(fd);
  if (s.ok() && ::rename(tmp.c_str(), path.c_str()) != 0) s = ErrnoError("cannot rename", tmp);
  if (!s.ok()) ::unlink(tmp.c_str());
  return s;
}

std::string Frame(const v1::JournalRecord& record) {
  const std::string payload = record.SerializeAsString();
  std::string out;
  out.reserve(kHeader + payload.size());
  PutU32(&out, kMagic);
  PutU32(&out, static_cast<uint32_t>(payload.size()));
  PutU32(&out, Crc32c(payload));
  out += payload;
  return out;
}

}  // namespace

uint32_t Crc32c(std::string_view bytes) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0x82F63B78u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char b : bytes) crc = table[(crc ^ b) & 0xff] ^ (crc >> 8);
  return crc ^ 0xFFFFFFFFu;
}

absl::StatusOr<std::unique_ptr<Journal>> Journal::Open(const std::string& data_dir) {
  const std::string jdir = (fs::path(data_dir) / "journal").string();
  const std::string idir = (fs::path(data_dir) / "inputs").string();
  std::error_code ec;
  fs::create_directories(jdir, ec);
  if (!ec) fs::create_directories(idir, ec);
  if (ec) return absl::FailedPreconditionError(absl::StrCat("cannot create ", jdir, ": ", ec.message()));
  std::unique_ptr<Journal> j(new Journal(jdir, idir));
  const std::string path = j->LogPath();
  ::unlink((path + ".tmp").c_str());  // a compaction interrupted by a crash
  int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) return ErrnoError("cannot open", path);
  std::string bytes;
  {
    char buf[1 << 16];
    for (;;) {
      ssize_t n = ::read(fd, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        absl::Status s = ErrnoError("cannot read", path);
        ::close(fd);
        return s;
      }
      if (n == 0) break;
      bytes.append(buf, static_cast<size_t>(n));
    }
  }
  size_t pos = 0;
  while (bytes.size() - pos >= kHeader) {
    const char* h = bytes.data() + pos;
    const uint32_t len = GetU32(h + 4);
    if (GetU32(h) != kMagic || len > kMaxRecord || bytes.size() - pos - kHeader < len) break;
    std::string_view payload(h + kHeader, len);
    if (Crc32c(payload) != GetU32(h + 8)) break;
    v1::JournalRecord rec;
    if (!rec.ParseFromArray(payload.data(), static_cast<int>(payload.size()))) break;
    j->replayed_.push_back(std::move(rec));
    pos += kHeader + len;
  }
  if (pos < bytes.size()) {
    // A torn append (crash mid-write) or a corrupt record: everything from it
    // on is dropped, so later appends follow the last good record.
    j->dropped_tail_bytes_ = bytes.size() - pos;
    if (::ftruncate(fd, static_cast<off_t>(pos)) != 0 || ::fsync(fd) != 0) {
      absl::Status s = ErrnoError("cannot truncate", path);
      ::close(fd);
      return s;
    }
  }
  if (::lseek(fd, 0, SEEK_END) < 0) {
    absl::Status s = ErrnoError("cannot seek", path);
    ::close(fd);
    return s;
  }
  std::scoped_lock lock(j->mu_);
  j->fd_ = fd;
  return j;
}

Journal::~Journal() {
  std::scoped_lock lock(mu_);
  if (fd_ >= 0) ::close(fd_);
}

std::vector<v1::JournalRecord> Journal::TakeReplayed() { return std::move(replayed_); }

absl::Status Journal::Append(const v1::JournalRecord& record, bool sync) {
  const std::string framed = Frame(record);
  std::scoped_lock lock(mu_);
  if (fd_ < 0) return absl::FailedPreconditionError("journal closed");
  // One write(2) per record on an O_APPEND-less fd we alone own; a crash
  // mid-write leaves a torn tail that Open drops.
  if (absl::Status s = WriteAll(fd_, framed, LogPath()); !s.ok()) return s;
  if (sync && ::fdatasync(fd_) != 0) return ErrnoError("cannot fdatasync", LogPath());
  ++appended_;
  return absl::OkStatus();
}

absl::Status Journal::Rewrite(const std::vector<v1::JournalRecord>& records) {
  std::string bytes;
  for (const v1::JournalRecord& r : records) bytes += Frame(r);
  std::scoped_lock lock(mu_);
  const std::string path = LogPath();
  if (absl::Status s = WriteFileAtomically(path, bytes); !s.ok()) return s;
  SyncDir(journal_dir_);
  int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return ErrnoError("cannot reopen", path);
  if (::lseek(fd, 0, SEEK_END) < 0) {
    ::close(fd);
    return ErrnoError("cannot seek", path);
  }
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
  appended_ = 0;
  return absl::OkStatus();
}

uint64_t Journal::appended_since_rewrite() const {
  std::scoped_lock lock(mu_);
  return appended_;
}

std::string Journal::InputPath(const std::string& job_id) const {
  return absl::StrCat(inputs_dir_, "/", job_id, ".req");
}

absl::Status Journal::PutInput(const std::string& job_id, const v1::SubmitJobRequest& request) {
  std::string bytes;
  if (!request.SerializeToString(&bytes)) {
    return absl::InternalError(absl::StrCat("cannot serialize the input of job ", job_id));
  }
  absl::Status s = WriteFileAtomically(InputPath(job_id), bytes);
  if (s.ok()) SyncDir(inputs_dir_);
  return s;
}

absl::StatusOr<v1::SubmitJobRequest> Journal::GetInput(const std::string& job_id) {
  const std::string path = InputPath(job_id);
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return absl::NotFoundError(absl::StrCat("the stored input of job ", job_id, " is missing"));
  std::string bytes;
  char buf[1 << 16];
  for (;;) {
    ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    bytes.append(buf, static_cast<size_t>(n));
  }
  ::close(fd);
  v1::SubmitJobRequest request;
  if (!request.ParseFromString(bytes)) {
    return absl::DataLossError(absl::StrCat("the stored input of job ", job_id, " is corrupt"));
  }
  return request;
}

void Journal::DeleteInput(const std::string& job_id) { ::unlink(InputPath(job_id).c_str()); }

std::vector<std::string> Journal::ListInputs() {
  std::vector<std::string> ids;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(inputs_dir_, ec)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".req") {
      ids.push_back(e.path().stem().string());
    } else if (e.path().extension() == ".tmp") {
      fs::remove(e.path(), ec);  // a write interrupted by a crash
    }
  }
  return ids;
}

}  // namespace svrc::server
