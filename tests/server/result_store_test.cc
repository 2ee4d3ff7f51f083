// DiskResultStore: atomic writes with sha256, chunked reads, quota, retention,
// reopening a data dir (indexes finished results, drops half-written ones).
#include "server/result_store.h"

#include <filesystem>
#include <fstream>

#include "core/util/sha256.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::server {
namespace {
namespace fs = std::filesystem;

std::string Bytes(size_t n, char seed) {
  std::string s(n, '\0');
  for (size_t i = 0; i < n; ++i) s[i] = static_cast<char>(seed + i * 7);
  return s;
}

TEST(DiskResultStoreTest, PutStatReadDelete) {
  const std::string dir = testing::MakeTempDir("store");
  auto store = DiskResultStore::Open(dir, 0);
  ASSERT_TRUE(store.ok()) << store.status();
  const std::string data = Bytes(3000, 'a');
  absl::StatusOr<StoredResult> put = (*store)->Put("job1", data);
  ASSERT_TRUE(put.ok()) << put.status();
  EXPECT_EQ(put->size, 3000u);
  EXPECT_EQ(put->sha256, util::Sha256Hex(data));
  EXPECT_EQ((*store)->Stat("job1")->sha256, put->sha256);
  EXPECT_EQ((*store)->UsedBytes(), 3000u);
  // No temp files left behind; the data file holds exactly the bytes.
  for (const auto& e : fs::directory_iterator(dir + "/results")) {
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
  }
  std::string joined;
  for (uint64_t off = 0; off < 3000; off += 1024) {
    absl::StatusOr<std::string> chunk = (*store)->Read("job1", off, 1024);
    ASSERT_TRUE(chunk.ok()) << chunk.status();
    EXPECT_EQ(chunk->size(), std::min<uint64_t>(1024, 3000 - off));
    joined += *chunk;
  }
  EXPECT_EQ(joined, data);
  EXPECT_EQ((*store)->Read("job1", 3000, 10)->size(), 0u);
  EXPECT_EQ((*store)->Read("job1", 3001, 10).status().code(), absl::StatusCode::kOutOfRange);
  EXPECT_EQ((*store)->Put("job1", "x").status().code(), absl::StatusCode::kAlreadyExists);
  ASSERT_TRUE((*store)->Delete("job1").ok());
  EXPECT_EQ((*store)->Stat("job1").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ((*store)->UsedBytes(), 0u);
  EXPECT_FALSE(fs::exists(dir + "/results/job1.svrc"));
}

TEST(DiskResultStoreTest, RejectsKeysThatAreNotPlainNames) {
  auto store = DiskResultStore::Open(testing::MakeTempDir("store"), 0);
  ASSERT_TRUE(store.ok());
  EXPECT_EQ((*store)->Put("../evil", "x").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ((*store)->Put("", "x").status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(DiskResultStoreTest, QuotaRefusesWhatDoesNotFit) {
  auto store = DiskResultStore::Open(testing::MakeTempDir("store"), 5000);
  ASSERT_TRUE(store.ok());
  ASSERT_TRUE((*store)->Put("a", Bytes(3000, 'a')).ok());
  absl::StatusOr<StoredResult> b = (*store)->Put("b", Bytes(3000, 'b'));
  EXPECT_EQ(b.status().code(), absl::StatusCode::kResourceExhausted) << b.status();
  ASSERT_TRUE((*store)->Delete("a").ok());
  EXPECT_TRUE((*store)->Put("b", Bytes(3000, 'b')).ok());
}

TEST(DiskResultStoreTest, RetentionRemovesOldResults) {
  auto store = DiskResultStore::Open(testing::MakeTempDir("store"), 0);
  ASSERT_TRUE(store.ok());
  ASSERT_TRUE((*store)->Put("old", "1234").ok());
  EXPECT_TRUE((*store)->RemoveOlderThan(absl::Now() - absl::Hours(1)).empty());
  EXPECT_EQ((*store)->RemoveOlderThan(absl::Now() + absl::Seconds(1)),
            std::vector<std::string>{"old"});
  EXPECT_EQ((*store)->Stat("old").status().code(), absl::StatusCode::kNotFound);
}

TEST(DiskResultStoreTest, ReopenIndexesResultsAndDropsPartialWrites) {
  const std::string dir = testing::MakeTempDir("store");
  {
    auto store = DiskResultStore::Open(dir, 0);
    ASSERT_TRUE(store.ok());
    ASSERT_TRUE((*store)->Put("kept", Bytes(100, 'k')).ok());
  }
  // A crash mid-write leaves a temp file, or data without its metadata.
  std::ofstream(dir + "/results/.tmp-x-0") << "partial";
  std::ofstream(dir + "/results/orphan.svrc") << "no meta";
  auto store = DiskResultStore::Open(dir, 0);
  ASSERT_TRUE(store.ok());
  EXPECT_EQ((*store)->Stat("kept")->size, 100u);
  EXPECT_EQ(*(*store)->Read("kept", 0, 1000), Bytes(100, 'k'));
  EXPECT_EQ((*store)->UsedBytes(), 100u);
  EXPECT_FALSE(fs::exists(dir + "/results/.tmp-x-0"));
  EXPECT_FALSE(fs::exists(dir + "/results/orphan.svrc"));
}

}  // namespace
}  // namespace svrc::server
