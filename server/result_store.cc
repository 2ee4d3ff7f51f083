#include "server/result_store.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/util/sha256.h"

namespace svrc::server {
namespace fs = std::filesystem;
namespace {

constexpr char kDataExt[] = ".svrc";
constexpr char kMetaExt[] = ".meta";
constexpr char kTmpPrefix[] = ".tmp-";

bool ValidKey(const std::string& key) {
  if (key.empty() || key.size() > 128) return false;
  for (char c : key) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')) return false;
  }
  return true;
}

absl::Status ErrnoError(const std::string& what, const std::string& path) {
  return absl::InternalError(absl::StrCat(what, " ", path, ": ", std::strerror(errno)));
}

// Writes `bytes` to `tmp`, fsyncs it and renames it over `path`: readers see
// the whole file or none.
absl::Status WriteAtomically(const std::string& tmp, const std::string& path,
                             std::string_view bytes) {
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return ErrnoError("cannot create", tmp);
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      absl::Status s = ErrnoError("cannot write", tmp);
      ::close(fd);
      ::unlink(tmp.c_str());
      return s;
    }
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    absl::Status s = ErrnoError("cannot flush", tmp);
    ::unlink(tmp.c_str());
    return s;
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    absl::Status s = ErrnoError("cannot rename to", path);
    ::unlink(tmp.c_str());
    return s;
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

}  // namespace

absl::StatusOr<std::unique_ptr<DiskResultStore>> DiskResultStore::Open(const std::string& data_dir,
                                                                       uint64_t quota_bytes) {
  const fs::path dir = fs::path(data_dir) / "results";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot create result directory ", dir.string(), ": ", ec.message()));
  }
  std::unique_ptr<DiskResultStore> store(new DiskResultStore(dir.string(), quota_bytes));
  std::scoped_lock lock(store->mu_);
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(kTmpPrefix, 0) == 0) {  // a write interrupted by a crash
      fs::remove(e.path(), ec);
      continue;
    }
    if (e.path().extension() != kMetaExt) continue;
    const std::string key = e.path().stem().string();
    std::ifstream in(e.path());
    std::string size_text, sha;
    int64_t created_unix = 0;
    uint64_t size = 0;
    in >> size_text >> sha >> created_unix;
    std::error_code size_ec;
    const uint64_t on_disk = fs::file_size(store->DataPath(key), size_ec);
    if (!in || !absl::SimpleAtoi(size_text, &size) || size_ec || on_disk != size ||
        sha.size() != 64) {
      store->RemoveFiles(key);
      continue;
    }
    store->index_[key] = StoredResult{size, sha, absl::FromUnixSeconds(created_unix)};
    store->used_ += size;
  }
  // Data files without metadata were never completed.
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    if (e.path().extension() == kDataExt && !store->index_.count(e.path().stem().string())) {
      fs::remove(e.path(), ec);
    }
  }
  return store;
}

std::string DiskResultStore::DataPath(const std::string& key) const {
  return absl::StrCat(dir_, "/", key, kDataExt);
}
std::string DiskResultStore::MetaPath(const std::string& key) const {
  return absl::StrCat(dir_, "/", key, kMetaExt);
}

void DiskResultStore::RemoveFiles(const std::string& key) {
  ::unlink(MetaPath(key).c_str());  // metadata first: a crash leaves an orphan, not a lie
  ::unlink(DataPath(key).c_str());
}

absl::StatusOr<StoredResult> DiskResultStore::Put(const std::string& key, std::string_view bytes) {
  if (!ValidKey(key)) return absl::InvalidArgumentError(absl::StrCat("bad result key '", key, "'"));
  uint64_t tmp_id;
  {
    std::scoped_lock lock(mu_);
    if (index_.count(key)) return absl::AlreadyExistsError(absl::StrCat("result ", key, " exists"));
    if (quota_ > 0 && used_ + reserved_ + bytes.size() > quota_) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "result store quota exceeded: ", used_ + reserved_, " of ", quota_, " bytes used, result is ",
          bytes.size(), " bytes"));
    }
    reserved_ += bytes.size();
    tmp_id = tmp_counter_++;
  }
  StoredResult result{bytes.size(), util::Sha256Hex(bytes), absl::Now()};
  const std::string tmp = absl::StrCat(dir_, "/", kTmpPrefix, key, "-", tmp_id);
  absl::Status s = WriteAtomically(tmp, DataPath(key), bytes);
  if (s.ok()) {
    s = WriteAtomically(tmp + kMetaExt, MetaPath(key),
                        absl::StrCat(result.size, " ", result.sha256, " ",
                                     absl::ToUnixSeconds(result.created), "\n"));
    if (!s.ok()) ::unlink(DataPath(key).c_str());
  }
  SyncDir(dir_);
  std::scoped_lock lock(mu_);
  reserved_ -= bytes.size();
  if (!s.ok()) return s;
  index_[key] = result;
  used_ += result.size;
  return result;
}

absl::StatusOr<StoredResult> DiskResultStore::Stat(const std::string& key) {
  std::scoped_lock lock(mu_);
  auto it = index_.find(key);
  if (it == index_.end()) return absl::NotFoundError(absl::StrCat("no result ", key));
  return it->second;
}

absl::StatusOr<std::string> DiskResultStore::Read(const std::string& key, uint64_t offset,
                                                  uint64_t max_bytes) {
  absl::StatusOr<StoredResult> st = Stat(key);
  if (!st.ok()) return st.status();
  if (offset > st->size) {
    return absl::OutOfRangeError(
        absl::StrCat("offset ", offset, " is past the end of the result (", st->size, " bytes)"));
  }
  const uint64_t n = std::min<uint64_t>(max_bytes, st->size - offset);
  std::string out(n, '\0');
  int fd = ::open(DataPath(key).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return ErrnoError("cannot open", DataPath(key));
  uint64_t done = 0;
  while (done < n) {
    ssize_t r = ::pread(fd, out.data() + done, n - done, static_cast<off_t>(offset + done));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) {
      absl::Status s = ErrnoError("cannot read", DataPath(key));
      ::close(fd);
      return r == 0 ? absl::DataLossError(absl::StrCat(DataPath(key), " is truncated")) : s;
    }
    done += static_cast<uint64_t>(r);
  }
  ::close(fd);
  return out;
}

absl::Status DiskResultStore::Delete(const std::string& key) {
  std::scoped_lock lock(mu_);
  auto it = index_.find(key);
  if (it == index_.end()) return absl::OkStatus();
  used_ -= it->second.size;
  index_.erase(it);
  RemoveFiles(key);
  return absl::OkStatus();
}

std::vector<std::string> DiskResultStore::RemoveOlderThan(absl::Time cutoff) {
  std::vector<std::string> removed;
  std::scoped_lock lock(mu_);
  for (auto it = index_.begin(); it != index_.end();) {
    if (it->second.created < cutoff) {
      removed.push_back(it->first);
      used_ -= it->second.size;
      RemoveFiles(it->first);
      it = index_.erase(it);
    } else {
      ++it;
    }
  }
  return removed;
}

uint64_t DiskResultStore::UsedBytes() {
  std::scoped_lock lock(mu_);
  return used_;
}

}  // namespace svrc::server
