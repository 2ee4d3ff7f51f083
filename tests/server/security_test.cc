// Authentication and isolation against a real svrc-server: bearer tokens
// (missing, wrong, another client's job), per-client job limits, and a TLS /
// mTLS round trip with certificates made by the openssl CLI in a temp dir.
#include <chrono>
#include <filesystem>
#include <thread>

#include "client/remote_client.h"
#include "gtest/gtest.h"
#include "tests/server/job_test_util.h"
#include "tests/server/service_test_util.h"
#include "tests/test_support.h"

namespace svrc {
namespace {

using testing::NodeRequest;
using testing::WaitTerminal;

using cli::ClientSecurity;
using cli::RemoteClient;
using testing::ServerProcess;
using Clock = std::chrono::steady_clock;

constexpr char kAliceToken[] = "alice-0123456789abcdef0123456789";
constexpr char kBobToken[] = "bob-fedcba9876543210fedcba987654";



class TempDir {
 public:
  TempDir() : path_(testing::MakeTempDir("security")) {}
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

std::string TokenFile(const TempDir& dir) {
  const std::string path = dir / "tokens";
  testing::WriteFileOrDie(path, absl::StrCat("# test tokens\n", kAliceToken, " alice\n",
                                             kBobToken, " bob\n"));
  return path;
}

ClientSecurity WithToken(const std::string& token) {
  ClientSecurity s;
  s.token = token;
  return s;
}

TEST(SecurityTest, MissingAndWrongTokensAreUnauthenticated) {
  TempDir dir;
  ServerProcess server({"--token-file=" + TokenFile(dir)});
  ASSERT_TRUE(server.ok());
  RemoteClient none(server.address());
  RemoteClient wrong(server.address(), WithToken("alice-0123456789abcdef0123456788"));
  for (RemoteClient* c : {&none, &wrong}) {
    EXPECT_EQ(c->Submit(NodeRequest(testing::RandomNodeFile(50, 1)), 1).status().code(),
              absl::StatusCode::kUnauthenticated);
    EXPECT_EQ(c->Get("j0").status().code(), absl::StatusCode::kUnauthenticated);
    EXPECT_EQ(c->List(v1::ListJobsRequest()).status().code(), absl::StatusCode::kUnauthenticated);
    EXPECT_EQ(c->Cancel("j0").status().code(), absl::StatusCode::kUnauthenticated);
    EXPECT_EQ(c->Delete("j0").code(), absl::StatusCode::kUnauthenticated);
    EXPECT_EQ(c->Watch("j0", nullptr, 0).status().code(), absl::StatusCode::kUnauthenticated);
    EXPECT_EQ(c->Fetch("j0", 1).status().code(), absl::StatusCode::kUnauthenticated);
  }
  // A big upload (streamed) without a token is refused too.
  v1::SubmitJobRequest big = NodeRequest(std::string(RemoteClient::kUnaryInputLimit + 10, '#'));
  EXPECT_EQ(none.Submit(big, 1).status().code(), absl::StatusCode::kUnauthenticated);
  // The health check stays open (probes carry no token).
  EXPECT_TRUE(*none.Serving());
  // Tokens never reach the log.
  const std::string log = server.Log();
  EXPECT_EQ(log.find("0123456789abcdef"), std::string::npos) << log;
  EXPECT_EQ(log.find("fedcba"), std::string::npos) << log;
  EXPECT_NE(log.find("invalid bearer token"), std::string::npos) << log;
}

TEST(SecurityTest, ClientsSeeOnlyTheirOwnJobs) {
  TempDir dir;
  ServerProcess server({"--token-file=" + TokenFile(dir)});
  ASSERT_TRUE(server.ok());
  RemoteClient alice(server.address(), WithToken(kAliceToken));
  RemoteClient bob(server.address(), WithToken(kBobToken));
  absl::StatusOr<v1::Job> job = alice.Submit(NodeRequest(testing::RandomNodeFile(1000, 2), "r1"));
  ASSERT_TRUE(job.ok()) << job.status();
  const std::string id = job->job_id();
  ASSERT_EQ(WaitTerminal(alice, id).state(), v1::SUCCEEDED);
  // Bob cannot see, watch, fetch, cancel or delete it: it does not exist for him.
  EXPECT_EQ(bob.Get(id).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(bob.Watch(id, nullptr, 0).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(bob.Fetch(id, 1).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(bob.Cancel(id).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(bob.Delete(id).code(), absl::StatusCode::kNotFound);
  absl::StatusOr<v1::ListJobsResponse> bobs = bob.List(v1::ListJobsRequest());
  ASSERT_TRUE(bobs.ok());
  EXPECT_EQ(bobs->jobs_size(), 0);
  // Request ids are per client: Bob's "r1" is a new job of his own.
  absl::StatusOr<v1::Job> bob_job = bob.Submit(NodeRequest(testing::RandomNodeFile(100, 3), "r1"));
  ASSERT_TRUE(bob_job.ok()) << bob_job.status();
  EXPECT_NE(bob_job->job_id(), id);
  // Alice still has hers, intact.
  absl::StatusOr<v1::ListJobsResponse> alices = alice.List(v1::ListJobsRequest());
  ASSERT_TRUE(alices.ok());
  ASSERT_EQ(alices->jobs_size(), 1);
  EXPECT_EQ(alices->jobs(0).job_id(), id);
  EXPECT_TRUE(alice.Fetch(id).ok());
  EXPECT_TRUE(alice.Delete(id).ok());
}

TEST(SecurityTest, PerClientJobLimit) {
  TempDir dir;
  ServerProcess server({"--token-file=" + TokenFile(dir), "--workers=1", "--max-jobs-per-client=1"});
  ASSERT_TRUE(server.ok());
  RemoteClient alice(server.address(), WithToken(kAliceToken));
  RemoteClient bob(server.address(), WithToken(kBobToken));
  absl::StatusOr<v1::Job> first = alice.Submit(NodeRequest(testing::RandomNodeFile(200000, 4)));
  ASSERT_TRUE(first.ok()) << first.status();
  absl::StatusOr<v1::Job> second = alice.Submit(NodeRequest(testing::RandomNodeFile(10, 5)));
  EXPECT_EQ(second.status().code(), absl::StatusCode::kResourceExhausted) << second.status();
  absl::StatusOr<v1::Job> other = bob.Submit(NodeRequest(testing::RandomNodeFile(100, 6)));
  ASSERT_TRUE(other.ok()) << other.status();  // the limit is per client
  EXPECT_EQ(WaitTerminal(alice, first->job_id()).state(), v1::SUCCEEDED);
  // Once the first one is done, Alice may submit again.
  EXPECT_TRUE(alice.Submit(NodeRequest(testing::RandomNodeFile(10, 7))).ok());
}

bool Openssl(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {"/usr/bin/openssl"};
  argv.insert(argv.end(), args.begin(), args.end());
  testing::CommandResult r = testing::RunCommand(argv);
  if (r.exit_code != 0) ADD_FAILURE() << "openssl failed: " << r.err;
  return r.exit_code == 0;
}

// A CA, and a server and a client certificate it signed (server SAN
// 127.0.0.1 and localhost), as PEM files in `dir`.
bool MakeCertificates(const TempDir& dir) {
  testing::WriteFileOrDie(dir / "server.ext",
                          "subjectAltName=IP:127.0.0.1,DNS:localhost\n"
                          "extendedKeyUsage=serverAuth\n");
  testing::WriteFileOrDie(dir / "client.ext", "extendedKeyUsage=clientAuth\n");
  return Openssl({"req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj",
                  "/CN=svrc test CA", "-keyout", dir / "ca.key", "-out", dir / "ca.pem"}) &&
         Openssl({"req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=localhost", "-keyout",
                  dir / "server.key", "-out", dir / "server.csr"}) &&
         Openssl({"x509", "-req", "-in", dir / "server.csr", "-CA", dir / "ca.pem", "-CAkey",
                  dir / "ca.key", "-CAcreateserial", "-days", "2", "-extfile", dir / "server.ext",
                  "-out", dir / "server.pem"}) &&
         Openssl({"req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=alice", "-keyout",
                  dir / "client.key", "-out", dir / "client.csr"}) &&
         Openssl({"x509", "-req", "-in", dir / "client.csr", "-CA", dir / "ca.pem", "-CAkey",
                  dir / "ca.key", "-CAcreateserial", "-days", "2", "-extfile", dir / "client.ext",
                  "-out", dir / "client.pem"});
}

TEST(SecurityTest, MutualTlsRoundTrip) {
  TempDir dir;
  ASSERT_TRUE(MakeCertificates(dir));
  ServerProcess server({"--token-file=" + TokenFile(dir), "--tls-cert=" + (dir / "server.pem"),
                        "--tls-key=" + (dir / "server.key"), "--tls-client-ca=" + (dir / "ca.pem")});
  ASSERT_TRUE(server.ok());
  ClientSecurity full;
  full.tls_ca = dir / "ca.pem";
  full.tls_cert = dir / "client.pem";
  full.tls_key = dir / "client.key";
  full.token = kAliceToken;
  RemoteClient alice(server.address(), full, absl::Seconds(10));
  absl::StatusOr<v1::Job> job = alice.Submit(NodeRequest(testing::RandomNodeFile(2000, 8)));
  ASSERT_TRUE(job.ok()) << job.status();
  ASSERT_EQ(WaitTerminal(alice, job->job_id()).state(), v1::SUCCEEDED);
  absl::StatusOr<cli::FetchedResult> result = alice.Fetch(job->job_id());
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_GT(result->bytes.size(), 0u);
  // Without a client certificate, or in plaintext, the handshake fails.
  ClientSecurity no_cert = full;
  no_cert.tls_cert.clear();
  no_cert.tls_key.clear();
  RemoteClient anonymous(server.address(), no_cert, absl::Seconds(5));
  EXPECT_EQ(anonymous.Get(job->job_id()).status().code(), absl::StatusCode::kUnavailable);
  RemoteClient plaintext(server.address(), WithToken(kAliceToken), absl::Seconds(5));
  EXPECT_EQ(plaintext.Get(job->job_id()).status().code(), absl::StatusCode::kUnavailable);
  // The CLI with the same files and the token from a file.
  testing::WriteFileOrDie(dir / "alice.token", std::string(kAliceToken) + "\n");
  testing::CommandResult get = testing::RunSvrc(
      {"get", job->job_id(), "--server", server.address(), "--tls-ca", dir / "ca.pem",
       "--tls-cert", dir / "client.pem", "--tls-key", dir / "client.key", "--token-file",
       dir / "alice.token"});
  EXPECT_EQ(get.exit_code, 0) << get.err;
  EXPECT_NE(get.out.find("SUCCEEDED"), std::string::npos) << get.out;
}

TEST(SecurityTest, ServerOnlyTlsWithTokenFromEnvironment) {
  TempDir dir;
  ASSERT_TRUE(MakeCertificates(dir));
  ServerProcess server({"--token-file=" + TokenFile(dir), "--tls-cert=" + (dir / "server.pem"),
                        "--tls-key=" + (dir / "server.key")});
  ASSERT_TRUE(server.ok());
  setenv("SVRC_TOKEN", kBobToken, 1);
  absl::StatusOr<ClientSecurity> s = cli::SecurityFromFlags(dir / "ca.pem", "", "", "");
  unsetenv("SVRC_TOKEN");
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_EQ(s->token, kBobToken);
  RemoteClient bob(server.address(), *s, absl::Seconds(10));
  absl::StatusOr<v1::ListJobsResponse> list = bob.List(v1::ListJobsRequest());
  EXPECT_TRUE(list.ok()) << list.status();
}

}  // namespace
}  // namespace svrc

namespace svrc {
namespace {

TEST(LimitsTest, JobOverItsMemoryBudgetEndsResourceExhaustedAndTheServerGoesOn) {
  ServerProcess server({"--workers=1", "--max-job-memory-mb=16"});
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  // 300k points: the Delaunay structure alone needs far more than 16 MiB.
  absl::StatusOr<v1::Job> big = c.Submit(NodeRequest(testing::RandomNodeFile(300000, 9)));
  ASSERT_TRUE(big.ok()) << big.status();
  const v1::Job done = WaitTerminal(c, big->job_id());
  EXPECT_EQ(done.state(), v1::FAILED);
  EXPECT_EQ(done.error().code(), static_cast<int>(absl::StatusCode::kResourceExhausted))
      << done.error().message();
  EXPECT_NE(done.error().message().find("memory budget"), std::string::npos)
      << done.error().message();
  // The next job (small) runs normally on the same server.
  absl::StatusOr<v1::Job> small = c.Submit(NodeRequest(testing::RandomNodeFile(2000, 10)));
  ASSERT_TRUE(small.ok()) << small.status();
  EXPECT_EQ(WaitTerminal(c, small->job_id()).state(), v1::SUCCEEDED);
}

}  // namespace
}  // namespace svrc
