#include "core/api.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <thread>

#include "core/mesh/quality.h"
#include "core/plc/readers.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::core {
namespace {

TEST(CancelTokenTest, ReportsCancelAndDeadline) {
  CancelToken token;
  EXPECT_TRUE(token.Check().ok());
  token.Cancel();
  EXPECT_EQ(token.Check().code(), absl::StatusCode::kCancelled);

  CancelToken timed(std::chrono::steady_clock::now() + std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(timed.Check().code(), absl::StatusCode::kDeadlineExceeded);
}

// The process's address space (VmSize), bytes.
uint64_t AddressSpaceBytes() {
  std::ifstream in("/proc/self/status");
  std::string key;
  while (in >> key) {
    if (key == "VmSize:") {
      uint64_t kb = 0;
      in >> kb;
      return kb * 1024;
    }
  }
  return 0;
}

// An allocation that fails ends the job with RESOURCE_EXHAUSTED, not the
// process (two facets at 0.1° under a 13 GB limit died of an uncaught
// std::bad_alloc, SIGABRT). In a child process whose address space may grow
// by 300 MB: a job needing gigabytes, ahead of its vertex budget.
TEST(MeshPlcTest, OutOfMemoryIsAnErrorNotACrash) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "sanitizers reserve the address space themselves";
#endif
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath("a_convex/cube.poly"));
  ASSERT_TRUE(plc.ok()) << plc.status();
  MeshParams params;
  params.max_volume = 1e-8;  // ~10^8 tets
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const rlim_t cap = AddressSpaceBytes() + (300u << 20);
    const rlimit lim{cap, cap};
    if (setrlimit(RLIMIT_AS, &lim) != 0) _exit(10);
    const absl::StatusOr<mesh::TetMesh> m = MeshPlc(*plc, params);
    if (m.ok()) _exit(11);
    if (m.status().code() != absl::StatusCode::kResourceExhausted) _exit(12);
    if (m.status().message().find("out of memory") == std::string_view::npos) _exit(13);
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "the child died of signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "10: setrlimit, 11: meshed, 12: another code, 13: another message";
}

// The CLI's huge-page re-execution's gate: long jobs off the collar path.
TEST(HugePageHeapPaysTest, LongJobsWithoutCollars) {
  MeshParams params;
  auto read = [](const char* rel) {
    absl::StatusOr<plc::Plc> p = plc::ReadPlcFile(testing::CorpusPath(rel));
    EXPECT_TRUE(p.ok()) << rel << ": " << p.status();
    return p.ok() ? *p : plc::Plc{};
  };
  const plc::Plc cube = read("a_convex/cube.poly");
  EXPECT_FALSE(HugePageHeapPays(cube, params));  // small
  EXPECT_FALSE(HugePageHeapPays(read("a_convex/tetra.poly"), params));
  // Regions with max volumes; its 63-degree crease is refined through without collars.
  EXPECT_TRUE(HugePageHeapPays(read("b_internal/example.poly"), params));
  const plc::Plc knife = read("c_creases/knife_edge.poly");
  EXPECT_FALSE(HugePageHeapPays(knife, params));                       // collars, small
  EXPECT_FALSE(HugePageHeapPays(read("f_real/bunny.off"), params));  // 3,485 points, collars
  plc::Plc regional = cube;
  regional.regions.push_back({{0.5, 0.5, 0.5}, 1, 1e-3});
  EXPECT_TRUE(HugePageHeapPays(regional, params));
  params.max_volume = 1e-3;
  EXPECT_TRUE(HugePageHeapPays(cube, params));
  EXPECT_FALSE(HugePageHeapPays(knife, params));  // a max volume, but collars (1.3-1.8x slower on huge pages)
  plc::Plc broken = knife;
  broken.facets[0].polygons[0].vertices[0] = 1u << 30;  // refused by PreparePlc: no guess
  EXPECT_FALSE(HugePageHeapPays(broken, params));
  plc::Plc points;  // a point set of 1,000 points: no creases
  for (int i = 0; i < 1000; ++i) points.vertices.push_back({0.001 * i, 0.37 * (i % 7), 0.11 * (i % 13)});
  params.max_volume = 0;
  EXPECT_TRUE(HugePageHeapPays(points, params));
}

// The sliver pass's stats are over the tets it works on, which are the
// output's: its worst angle and radius-edge after the flips are the output
// mesh's (up to the rounding of the map back to input coordinates). With the
// exterior tets counted, cube --max-volume 1e-3 reported 0.62° and 48.8 for an
// output of 15.05° and 1.29 (session 49).
TEST(MeshPlcTest, SliverStatsDescribeTheOutput) {
  for (const auto& [rel, max_volume] :
       std::vector<std::pair<const char*, double>>{{"a_convex/cube.poly", 1e-3}, {"b_internal/box_in_box.poly", 0}}) {
    SCOPED_TRACE(rel);
    absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath(rel));
    ASSERT_TRUE(plc.ok()) << plc.status();
    MeshParams params;
    params.max_volume = max_volume;
    const absl::StatusOr<mesh::TetMesh> m = MeshPlc(*plc, params);
    ASSERT_TRUE(m.ok()) << m.status();
    const mesh::QualityReport q = mesh::ComputeQuality(*m);
    ASSERT_GT(q.all.num_tets, 0u);
    const double min_after = m->stats.Get("sliver.min_dihedral_after", -1);
    const double re_after = m->stats.Get("sliver.max_radius_edge_after", -1);
    EXPECT_NEAR(min_after, q.all.min_dihedral_deg.min, 1e-6 * q.all.min_dihedral_deg.min);
    EXPECT_NEAR(re_after, q.all.radius_edge.max, 1e-6 * q.all.radius_edge.max);
    EXPECT_NEAR(m->stats.Get("sliver.max_dihedral_after", -1), q.all.dihedral_deg.max, 1e-6 * q.all.dihedral_deg.max);
    EXPECT_LE(m->stats.Get("sliver.max_radius_edge_before", 1e9), params.radius_edge * (1 + 1e-9));
    // The pass counts every tet, exterior included.
    EXPECT_GT(m->stats.Get("sliver.tets_after"), static_cast<double>(m->tets.size()));
  }
}

TEST(VersionTest, NamesTheProject) { EXPECT_EQ(Version().rfind("svrc ", 0), 0u); }

}  // namespace
}  // namespace svrc::core
