// The `svrc` CLI binary against a real server: local and remote outputs are
// byte-identical in every output format; the job id is submit's last stdout
// line; get/list/cancel/health work; exit statuses follow client/command.h
// (2 usage, 3 invalid input, 4 server, 5 job failed, 6 cancelled/deadline).
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "tests/server/service_test_util.h"
#include "tests/test_support.h"

namespace svrc {
namespace {

namespace fs = std::filesystem;
using testing::RunSvrc;
using testing::ServerProcess;

// Every file in `dir`, by name → bytes.
std::map<std::string, std::string> DirFiles(const std::string& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    out[e.path().filename().string()] = testing::ReadFileOrFail(e.path().string());
  }
  return out;
}

class CliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { server_ = new ServerProcess({"--workers=2"}); }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
  }
  static ServerProcess* server_;
};
ServerProcess* CliTest::server_ = nullptr;

TEST_F(CliTest, LocalAndRemoteOutputsAreByteIdentical) {
  ASSERT_TRUE(server_->ok());
  const std::string dir = testing::MakeTempDir("cli_identity");
  const std::string input = dir + "/points.node";
  testing::WriteFileOrDie(input, testing::RandomNodeFile(5000, 21));
  for (const char* ext : {".node", ".vtu", ".msh", ".mesh", ".svrc"}) {
    SCOPED_TRACE(ext);
    const std::string local_dir = dir + "/local" + ext, remote_dir = dir + "/remote" + ext;
    fs::create_directories(local_dir);
    fs::create_directories(remote_dir);
    testing::CommandResult local =
        RunSvrc({"mesh", input, "-o", local_dir + "/out" + ext, "--quiet"});
    ASSERT_EQ(local.exit_code, 0) << local.err;
    testing::CommandResult remote = RunSvrc({"submit", input, "--server", server_->address(),
                                             "--watch", "-o", remote_dir + "/out" + ext});
    ASSERT_EQ(remote.exit_code, 0) << remote.err;
    std::map<std::string, std::string> a = DirFiles(local_dir), b = DirFiles(remote_dir);
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(a.size(), b.size());
    for (const auto& [name, bytes] : a) {
      ASSERT_TRUE(b.count(name)) << name << " missing remotely";
      EXPECT_TRUE(bytes == b[name]) << name << " differs (" << bytes.size() << " vs "
                                    << b[name].size() << " bytes)";
    }
  }
  EXPECT_TRUE(fs::exists(dir + "/local.node/out.ele"));
  EXPECT_TRUE(fs::exists(dir + "/local.node/out.face"));
  fs::remove_all(dir);
}

// The same for a PLC (SVRC refinement, facets and regions in the output; issue
// #5): `svrc mesh` twice and `svrc submit --watch` agree byte for byte.
TEST_F(CliTest, PlcLocalAndRemoteOutputsAreByteIdentical) {
  ASSERT_TRUE(server_->ok());
  const std::string dir = testing::MakeTempDir("cli_plc_identity");
  const std::string input = testing::CorpusPath("b_internal/box_internal_facet.poly");
  for (const char* ext : {".node", ".vtu", ".svrc"}) {
    SCOPED_TRACE(ext);
    std::map<std::string, std::string> outputs[3];
    for (int run = 0; run < 3; ++run) {
      const std::string out_dir = dir + "/run" + std::to_string(run) + ext;
      fs::create_directories(out_dir);
      testing::CommandResult r =
          run < 2 ? RunSvrc({"mesh", input, "-o", out_dir + "/out" + ext, "--quiet"})
                  : RunSvrc({"submit", input, "--server", server_->address(), "--watch", "-o",
                             out_dir + "/out" + ext});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      outputs[run] = DirFiles(out_dir);
    }
    ASSERT_FALSE(outputs[0].empty());
    for (int run = 1; run < 3; ++run) {
      EXPECT_EQ(outputs[run].size(), outputs[0].size()) << "run " << run;
      for (const auto& [name, bytes] : outputs[0]) {
        ASSERT_TRUE(outputs[run].count(name)) << name << " missing in run " << run;
        EXPECT_TRUE(bytes == outputs[run][name]) << name << " differs in run " << run << " ("
                                                 << bytes.size() << " vs " << outputs[run][name].size()
                                                 << " bytes)";
      }
    }
  }
  // A PLC's .node output has its boundary faces (markers) next to it.
  EXPECT_TRUE(fs::exists(dir + "/run0.node/out.face"));
  fs::remove_all(dir);
}

// A creased input with a collar option (--collar-size-eps, the Ch. 6 size
// criterion; --collar-cell-test, the thesis' cell test instead of the
// per-tet test): the flag reaches the server's mesher (proto fields
// collar_size_eps, collar_cell_test), so local and remote .svrc outputs are
// byte-identical, and they differ from the defaults'.
TEST_F(CliTest, CollarOptionLocalAndRemoteOutputsAreByteIdentical) {
  ASSERT_TRUE(server_->ok());
  const std::string dir = testing::MakeTempDir("cli_collar_identity");
  const std::string input = testing::CorpusPath("c_creases/knife_edge.poly");
  const testing::CommandResult plain = RunSvrc({"mesh", input, "-o", dir + "/plain.svrc", "--quiet"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  for (const std::vector<std::string>& flags :
       {std::vector<std::string>{"--collar-size-eps", "0.3"}, std::vector<std::string>{"--collar-cell-test"}}) {
    std::vector<std::string> mesh = {"mesh", input, "-o", dir + "/local.svrc", "--quiet"};
    std::vector<std::string> submit = {"submit", input, "--server", server_->address(), "--watch",
                                       "-o", dir + "/remote.svrc"};
    mesh.insert(mesh.end(), flags.begin(), flags.end());
    submit.insert(submit.end(), flags.begin(), flags.end());
    const testing::CommandResult local = RunSvrc(mesh);
    ASSERT_EQ(local.exit_code, 0) << flags[0] << ": " << local.err;
    const testing::CommandResult remote = RunSvrc(submit);
    ASSERT_EQ(remote.exit_code, 0) << flags[0] << ": " << remote.err;
    const std::string a = testing::ReadFileOrFail(dir + "/local.svrc");
    EXPECT_TRUE(a == testing::ReadFileOrFail(dir + "/remote.svrc")) << flags[0];
    EXPECT_FALSE(a == testing::ReadFileOrFail(dir + "/plain.svrc")) << flags[0];
  }
  EXPECT_EQ(RunSvrc({"mesh", input, "-o", dir + "/x.svrc", "--collar-size-eps", "1.5"}).exit_code, 2);
  fs::remove_all(dir);
}

// --min-dihedral (docs/svrc-design.md §8 item 69) reaches the server's
// mesher (the same .svrc bytes locally and remotely, unlike the default's),
// a target the rounds cannot reach is reported on stderr both ways, a
// reachable one is not, and one no tet can meet is a usage error.
TEST_F(CliTest, MinDihedralLocalAndRemoteAndItsWarning) {
  ASSERT_TRUE(server_->ok());
  const std::string dir = testing::MakeTempDir("cli_min_dihedral");
  const std::string input = testing::CorpusPath("e_spread/tiny_cube_in_box.poly");
  const testing::CommandResult plain = RunSvrc({"mesh", input, "-o", dir + "/plain.svrc", "--quiet"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const testing::CommandResult met =
      RunSvrc({"mesh", input, "-o", dir + "/met.svrc", "--quiet", "--min-dihedral", "20"});
  ASSERT_EQ(met.exit_code, 0) << met.err;
  EXPECT_EQ(met.err.find("warning"), std::string::npos) << met.err;
  const testing::CommandResult local =
      RunSvrc({"mesh", input, "-o", dir + "/local.svrc", "--quiet", "--min-dihedral", "35"});
  ASSERT_EQ(local.exit_code, 0) << local.err;
  EXPECT_NE(local.err.find("warning: "), std::string::npos) << local.err;
  EXPECT_NE(local.err.find("below min_dihedral 35 degrees"), std::string::npos) << local.err;
  const testing::CommandResult remote = RunSvrc({"submit", input, "--server", server_->address(), "--watch", "-o",
                                                 dir + "/remote.svrc", "--min-dihedral", "35"});
  ASSERT_EQ(remote.exit_code, 0) << remote.err;
  EXPECT_NE(remote.err.find("below min_dihedral 35 degrees"), std::string::npos) << remote.err;
  const std::string a = testing::ReadFileOrFail(dir + "/local.svrc");
  EXPECT_TRUE(a == testing::ReadFileOrFail(dir + "/remote.svrc"));
  EXPECT_FALSE(a == testing::ReadFileOrFail(dir + "/plain.svrc"));
  EXPECT_FALSE(a == testing::ReadFileOrFail(dir + "/met.svrc"));
  EXPECT_EQ(RunSvrc({"mesh", input, "-o", dir + "/x.svrc", "--min-dihedral", "75"}).exit_code, 2);
  fs::remove_all(dir);
}

TEST_F(CliTest, SubmitPrintsTheJobIdThenGetListAndHealthWork) {
  ASSERT_TRUE(server_->ok());
  const std::string dir = testing::MakeTempDir("cli_submit");
  const std::string input = dir + "/p.node";
  testing::WriteFileOrDie(input, testing::RandomNodeFile(300, 22));
  testing::CommandResult sub = RunSvrc({"submit", input, "--server", server_->address()});
  ASSERT_EQ(sub.exit_code, 0) << sub.err;
  const std::string id = testing::LastLine(sub.out);
  ASSERT_EQ(id.size(), 17u) << sub.out;
  testing::CommandResult watch = RunSvrc({"watch", id, "--server", server_->address()});
  EXPECT_EQ(watch.exit_code, 0) << watch.err;
  EXPECT_NE(watch.out.find("SUCCEEDED"), std::string::npos) << watch.out;
  testing::CommandResult get = RunSvrc({"get", id, "--server", server_->address(), "-o", dir + "/r.vtu"});
  EXPECT_EQ(get.exit_code, 0) << get.err;
  EXPECT_TRUE(fs::exists(dir + "/r.vtu"));
  testing::CommandResult list = RunSvrc({"list", "--server", server_->address(), "--state", "SUCCEEDED"});
  EXPECT_EQ(list.exit_code, 0) << list.err;
  EXPECT_NE(list.out.find(id), std::string::npos) << list.out;
  testing::CommandResult health = RunSvrc({"health", "--server", server_->address()});
  EXPECT_EQ(health.exit_code, 0) << health.err;
  EXPECT_EQ(testing::LastLine(health.out), "SERVING");
  // Same --request-id: same job.
  testing::CommandResult r1 = RunSvrc({"submit", input, "--server", server_->address(), "--request-id", "cli-rid-1"});
  testing::CommandResult r2 = RunSvrc({"submit", input, "--server", server_->address(), "--request-id", "cli-rid-1"});
  EXPECT_EQ(testing::LastLine(r1.out), testing::LastLine(r2.out));
  testing::CommandResult del = RunSvrc({"delete", id, "--server", server_->address()});
  EXPECT_EQ(del.exit_code, 0) << del.err;
  EXPECT_EQ(RunSvrc({"get", id, "--server", server_->address()}).exit_code, 4);
}

TEST_F(CliTest, ExitStatuses) {
  ASSERT_TRUE(server_->ok());
  const std::string dir = testing::MakeTempDir("cli_exit");
  const std::string bad = testing::CorpusPath("g_bad/bad_dangling_index.poly");
  const std::string cube = testing::CorpusPath("a_convex/cube.poly");
  const std::string points = dir + "/p.node";
  testing::WriteFileOrDie(points, testing::RandomNodeFile(200, 23));

  EXPECT_EQ(RunSvrc({}).exit_code, 2);
  EXPECT_EQ(RunSvrc({"frobnicate"}).exit_code, 2);
  EXPECT_EQ(RunSvrc({"mesh", points}).exit_code, 2);  // no -o
  EXPECT_EQ(RunSvrc({"mesh", points, "-o", dir + "/x.vtu", "--radius-edge", "abc"}).exit_code, 2);
  EXPECT_EQ(RunSvrc({"submit", points, "--no-such-flag"}).exit_code, 2);

  testing::CommandResult local_bad = RunSvrc({"mesh", bad, "-o", dir + "/b.vtu"});
  EXPECT_EQ(local_bad.exit_code, 3);
  EXPECT_NE(local_bad.err.find("42"), std::string::npos) << local_bad.err;
  EXPECT_EQ(std::count(local_bad.err.begin(), local_bad.err.end(), '\n'), 1) << local_bad.err;
  testing::CommandResult remote_bad = RunSvrc({"submit", bad, "--server", server_->address(), "--watch"});
  EXPECT_EQ(remote_bad.exit_code, 3) << remote_bad.err;
  EXPECT_NE(remote_bad.err.find("INVALID_ARGUMENT"), std::string::npos) << remote_bad.err;
  EXPECT_EQ(RunSvrc({"mesh", dir + "/missing.node", "-o", dir + "/m.vtu"}).exit_code, 3);

  // Unreachable server: 4 (a port nothing listens on: the server's own, after it is gone).
  {
    ServerProcess gone;
    ASSERT_TRUE(gone.ok());
    const std::string addr = gone.address();
    gone.Terminate(30);
    EXPECT_EQ(RunSvrc({"health", "--server", addr}).exit_code, 4);
    EXPECT_EQ(RunSvrc({"submit", points, "--server", addr}).exit_code, 4);
  }

  // A PLC job succeeds (0). A refinement parameter on a point set is
  // UNIMPLEMENTED: the job fails (5).
  EXPECT_EQ(RunSvrc({"submit", cube, "--server", server_->address(), "--watch"}).exit_code, 0);
  testing::CommandResult unimpl =
      RunSvrc({"submit", points, "--server", server_->address(), "--watch", "--max-volume", "0.1"});
  EXPECT_EQ(unimpl.exit_code, 5) << unimpl.err;
  EXPECT_NE(unimpl.err.find("UNIMPLEMENTED"), std::string::npos) << unimpl.err;
  EXPECT_EQ(RunSvrc({"mesh", points, "-o", dir + "/u.vtu", "--max-volume", "0.1"}).exit_code, 5);

  // Deadline exceeded (6), remotely and locally.
  const std::string big = dir + "/big.node";
  testing::WriteFileOrDie(big, testing::RandomNodeFile(400000, 24));
  testing::CommandResult late =
      RunSvrc({"submit", big, "--server", server_->address(), "--watch", "--deadline", "0.3s"});
  EXPECT_EQ(late.exit_code, 6) << late.err;
  EXPECT_NE(late.err.find("DEADLINE_EXCEEDED"), std::string::npos) << late.err;
  EXPECT_EQ(RunSvrc({"mesh", big, "-o", dir + "/late.vtu", "--deadline", "0.3", "--quiet"}).exit_code, 6);

  // Cancelled (6): watch a job that another command cancels.
  testing::CommandResult sub = RunSvrc({"submit", big, "--server", server_->address()});
  ASSERT_EQ(sub.exit_code, 0) << sub.err;
  const std::string id = testing::LastLine(sub.out);
  EXPECT_EQ(RunSvrc({"cancel", id, "--server", server_->address()}).exit_code, 0);
  EXPECT_EQ(RunSvrc({"watch", id, "--server", server_->address()}).exit_code, 6);
  EXPECT_EQ(RunSvrc({"get", id, "--server", server_->address(), "-o", dir + "/c.vtu"}).exit_code, 6);
  fs::remove_all(dir);
}

// `svrc` holds the local commands and links no service library (they made
// its start-up three times slower); a remote command runs svrc-remote beside
// it (client/remote_commands.h). The CliTest cases above go through that
// hand-over on every submit/watch/get.
TEST(CliSplitTest, TheLocalBinaryLinksNoServiceLibrary) {
  const testing::CommandResult needed = testing::RunCommand({"/usr/bin/readelf", "-d", testing::SvrcCliPath()});
  ASSERT_EQ(needed.exit_code, 0) << needed.err;
  ASSERT_TRUE(absl::StrContains(needed.out, "(NEEDED)")) << needed.out;
  for (const char* lib : {"libgrpc", "libprotobuf", "libssl", "libcrypto", "libupb", "libgpr"}) {
    EXPECT_FALSE(absl::StrContains(needed.out, lib)) << lib << " in\n" << needed.out;
  }
}

TEST(CliSplitTest, HelpListsTheRemoteCommandsAndAMissingRemoteBinaryIsNamed) {
  const testing::CommandResult help = RunSvrc({"--help"});
  EXPECT_EQ(help.exit_code, 0);
  for (const char* c : {"svrc mesh ", "svrc validate ", "svrc submit ", "svrc watch ", "svrc get ", "svrc cancel ",
                        "svrc delete ", "svrc list ", "svrc health "}) {
    EXPECT_TRUE(absl::StrContains(help.out, c)) << c << " missing from\n" << help.out;
  }
  // A copy of svrc alone in a folder, with a PATH that holds no svrc-remote.
  const std::string dir = testing::MakeTempDir("cli_lone");
  const std::string lone = dir + "/svrc";
  fs::copy_file(testing::SvrcCliPath(), lone);
  fs::permissions(lone, fs::perms::owner_all);
  const testing::CommandResult r =
      testing::RunCommand({"/usr/bin/env", "PATH=" + dir, lone, "list", "--server", "127.0.0.1:1"});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_TRUE(absl::StrContains(r.err, "'list' talks to a server")) << r.err;
  EXPECT_TRUE(absl::StrContains(r.err, dir + "/svrc-remote (No such file or directory)")) << r.err;
  // Local commands still work there.
  const testing::CommandResult v =
      testing::RunCommand({lone, "validate", testing::CorpusPath("a_convex/cube.poly"), "-q"});
  EXPECT_EQ(v.exit_code, 0) << v.err;
  fs::remove_all(dir);
}

// core/util/huge_pages.h: a long local job off the collar path re-executes
// itself once with glibc.malloc.hugetlb=1 when transparent huge pages are in
// madvise mode, a small one and a collar job do not, SVRC_HUGE_PAGES=0 turns
// it off, and the output bytes do not depend on it.
TEST(CliHugePagesTest, LongJobsRunOnAHugePageHeapWithTheSameOutput) {
  std::string mode;
  {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::getline(in, mode);
  }
  const bool madvise = absl::StrContains(mode, "[madvise]");
  const std::string dir = testing::MakeTempDir("cli_huge");
  const std::string cube = testing::CorpusPath("a_convex/cube.poly");
  auto flag = [](const testing::CommandResult& r) {
    if (absl::StrContains(r.out, "cli.huge_page_heap                 1")) return 1;
    if (absl::StrContains(r.out, "cli.huge_page_heap                 0")) return 0;
    return -1;
  };
  const testing::CommandResult small = RunSvrc({"mesh", cube, "-o", dir + "/small.node", "--quiet", "--stats"});
  ASSERT_EQ(small.exit_code, 0) << small.err;
  EXPECT_EQ(flag(small), 0) << small.out;  // no max_volume, 8 points, no crease: not worth a second start-up
  const testing::CommandResult big =
      RunSvrc({"mesh", cube, "--max-volume", "1e-3", "-o", dir + "/big.node", "--quiet", "--stats"});
  ASSERT_EQ(big.exit_code, 0) << big.err;
  EXPECT_EQ(flag(big), madvise ? 1 : 0) << mode << "\n" << big.out;
  const testing::CommandResult off =
      testing::RunCommand({"/usr/bin/env", "SVRC_HUGE_PAGES=0", testing::SvrcCliPath(), "mesh", cube, "--max-volume",
                           "1e-3", "-o", dir + "/off.node", "--quiet", "--stats"});
  ASSERT_EQ(off.exit_code, 0) << off.err;
  EXPECT_EQ(flag(off), 0) << off.out;
  for (const char* ext : {".node", ".ele", ".face"}) {
    EXPECT_EQ(testing::ReadFileOrFail(dir + "/big" + ext), testing::ReadFileOrFail(dir + "/off" + ext)) << ext;
  }
  // A collar job stays on the ordinary heap, max_volume or not: on the huge-page
  // heap they ran 1.3-1.8x slower (session 24).
  const testing::CommandResult knife = RunSvrc({"mesh", testing::CorpusPath("c_creases/knife_edge.poly"),
                                                "--max-volume", "1e-2", "-o", dir + "/knife.node", "--quiet",
                                                "--stats"});
  ASSERT_EQ(knife.exit_code, 0) << knife.err;
  EXPECT_EQ(flag(knife), 0) << knife.out;
  // An input that is not a regular file cannot be read twice: a FIFO named
  // .poly is read once and meshed in the same process (before the check the
  // re-executed process waited on the emptied FIFO forever).
  const std::string fifo = dir + "/fifo.poly";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] {
    std::ofstream(fifo) << testing::ReadFileOrFail(cube);
  });
  const testing::CommandResult piped =
      RunSvrc({"mesh", fifo, "--max-volume", "1e-3", "-o", dir + "/piped.node", "--quiet", "--stats", "--deadline",
               "60s"});
  writer.join();
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_EQ(flag(piped), 0) << piped.out;
  EXPECT_EQ(testing::ReadFileOrFail(dir + "/piped.ele"), testing::ReadFileOrFail(dir + "/off.ele"));
  fs::remove_all(dir);
}

TEST(CliVersionTest, PrintsTheVersion) {
  testing::CommandResult v = RunSvrc({"--version"});
  EXPECT_EQ(v.exit_code, 0);
  EXPECT_TRUE(absl::StartsWith(v.out, "svrc ")) << v.out;
}

}  // namespace
}  // namespace svrc
