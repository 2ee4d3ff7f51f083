// End to end against a real svrc-server process on a free loopback port,
// driven by the C++ client library (client/remote_client.h): submit → watch →
// fetch → decode, progress events, cancel, N workers, queue full, idempotent
// resubmission, deadlines, a broken PLC, a PLC's output byte-identical across
// runs and worker counts, resumable fetch, a 50 MB upload, SIGTERM. Point-set and PLC jobs make real meshes.
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "client/mesh_job.h"
#include "client/remote_client.h"
#include "core/codec/container.h"
#include "core/plc/readers.h"
#include "core/util/sha256.h"
#include "grpcpp/client_context.h"
#include "gtest/gtest.h"
#include "proto/convert.h"
#include "tests/server/service_test_util.h"
#include "tests/test_support.h"

namespace svrc {
namespace {

using cli::RemoteClient;
using testing::ServerProcess;
using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

v1::SubmitJobRequest NodeRequest(const std::string& node) {
  v1::SubmitJobRequest r;
  r.mutable_file()->set_format(v1::NODE);
  r.mutable_file()->set_name("points.node");
  r.mutable_file()->set_data(node);
  return r;
}

// Large enough that meshing takes seconds (and is uploaded in chunks).
const std::string& BigNode() {
  static const std::string node = testing::RandomNodeFile(400000, 77);
  return node;
}

v1::Job WaitState(RemoteClient& c, const std::string& id, v1::JobState state, double timeout_s = 60) {
  const auto t0 = Clock::now();
  absl::StatusOr<v1::Job> job;
  while (Since(t0) < timeout_s) {
    job = c.Get(id);
    if (job.ok() && job->state() == state) return *job;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ADD_FAILURE() << "job " << id << " never reached " << v1::JobState_Name(state) << ": "
                << (job.ok() ? v1::JobState_Name(job->state()) : job.status().ToString());
  return job.ok() ? *job : v1::Job();
}

std::string LocalContainer(const std::string& node, const cli::MeshOptions& options = {}) {
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcBytes(node, plc::InputFormat::kNode, "points.node");
  EXPECT_TRUE(plc.ok()) << plc.status();
  absl::StatusOr<mesh::TetMesh> mesh = cli::RunMeshing(*plc, options, nullptr, nullptr);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  codec::EncodeOptions eo;
  eo.position_quantization_bits = options.quantization_bits;
  return *codec::EncodeTetMesh(*mesh, eo);
}

TEST(ServiceTest, SubmitWatchFetchDecodeMatchesLocalBytes) {
  ServerProcess server({"--workers=2"});
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  ASSERT_TRUE(*c.Serving());
  const std::string node = testing::RandomNodeFile(3000, 11);
  absl::StatusOr<v1::Job> job = c.Submit(NodeRequest(node));
  ASSERT_TRUE(job.ok()) << job.status();
  EXPECT_EQ(job->state(), v1::QUEUED);
  EXPECT_FALSE(job->request_id().empty());  // the client fills one in
  std::vector<v1::JobEvent> events;
  absl::StatusOr<v1::Job> done = c.Watch(job->job_id(), [&](const v1::JobEvent& e) { events.push_back(e); });
  ASSERT_TRUE(done.ok()) << done.status();
  ASSERT_EQ(done->state(), v1::SUCCEEDED) << done->error().message();
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().job().state(), v1::SUCCEEDED);
  for (size_t i = 1; i < events.size(); ++i) EXPECT_GT(events[i].sequence(), events[i - 1].sequence());

  absl::StatusOr<cli::FetchedResult> result = c.Fetch(job->job_id());
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->bytes.size(), done->result().size_bytes());
  EXPECT_EQ(result->sha256, done->result().sha256());
  EXPECT_EQ(result->bytes, LocalContainer(node));  // byte-identical to a local run
  absl::StatusOr<mesh::TetMesh> mesh = codec::DecodeTetMesh(result->bytes);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->num_vertices(), 3000u);
  EXPECT_EQ(mesh->num_tets(), done->result().num_tets());
  EXPECT_EQ(mesh->provenance.input_sha256, util::Sha256Hex(node));
}

TEST(ServiceTest, StructuredPlcMessageGivesTheSameMeshAsTheFile) {
  ServerProcess server;
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  const std::string node = testing::RandomNodeFile(500, 12);
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcBytes(node, plc::InputFormat::kNode, "p.node");
  ASSERT_TRUE(plc.ok());
  v1::SubmitJobRequest structured;
  api::PlcToProto(*plc, structured.mutable_plc());
  absl::StatusOr<v1::Job> a = c.Submit(structured);
  absl::StatusOr<v1::Job> b = c.Submit(NodeRequest(node));
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(c.Watch(a->job_id(), nullptr)->state(), v1::SUCCEEDED);
  ASSERT_EQ(c.Watch(b->job_id(), nullptr)->state(), v1::SUCCEEDED);
  absl::StatusOr<mesh::TetMesh> ma = codec::DecodeTetMesh(c.Fetch(a->job_id())->bytes);
  absl::StatusOr<mesh::TetMesh> mb = codec::DecodeTetMesh(c.Fetch(b->job_id())->bytes);
  ASSERT_TRUE(ma.ok() && mb.ok());
  EXPECT_EQ(ma->tets, mb->tets);
  ASSERT_EQ(ma->positions.size(), mb->positions.size());
  for (size_t i = 0; i < ma->positions.size(); ++i) {
    EXPECT_EQ(ma->positions[i].x, mb->positions[i].x);
    EXPECT_EQ(ma->positions[i].z, mb->positions[i].z);
  }
}

TEST(ServiceTest, LongJobStreamsSeveralProgressEventsWithIncreasingCounters) {
  ServerProcess server({"--workers=1"});
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::Job> job = c.Submit(NodeRequest(BigNode()));  // > 4 MiB: UploadJob
  ASSERT_TRUE(job.ok()) << job.status();
  EXPECT_EQ(job->input_bytes(), BigNode().size());
  std::vector<v1::JobEvent> events;
  absl::StatusOr<v1::Job> done = c.Watch(job->job_id(), [&](const v1::JobEvent& e) { events.push_back(e); });
  ASSERT_TRUE(done.ok()) << done.status();
  ASSERT_EQ(done->state(), v1::SUCCEEDED) << done->error().message();
  EXPECT_EQ(done->result().num_vertices(), 400000u);
  int running = 0;
  const v1::JobEvent* prev = nullptr;
  for (const v1::JobEvent& e : events) {
    if (e.job().state() != v1::RUNNING) continue;
    ++running;
    if (prev != nullptr) {
      EXPECT_GE(e.job().progress().elapsed_seconds(), prev->job().progress().elapsed_seconds());
      if (e.job().progress().phase() == prev->job().progress().phase()) {
        EXPECT_GE(e.job().progress().vertices(), prev->job().progress().vertices());
      }
    }
    prev = &e;
  }
  EXPECT_GE(running, 5) << "elapsed " << done->progress().elapsed_seconds() << " s";
  std::printf("[ info ] 400k-point job: %.2f s, %d RUNNING events\n",
              done->progress().elapsed_seconds(), running);
}

TEST(ServiceTest, CancelRunningJobEndsCancelledAndTheWorkerRunsTheNextJob) {
  ServerProcess server({"--workers=1"});
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::Job> big = c.Submit(NodeRequest(BigNode()));
  ASSERT_TRUE(big.ok()) << big.status();
  absl::StatusOr<v1::Job> next = c.Submit(NodeRequest(testing::RandomNodeFile(100, 13)));
  ASSERT_TRUE(next.ok());
  WaitState(c, big->job_id(), v1::RUNNING);
  // Let the mesher get going, then cancel.
  const auto t_run = Clock::now();
  while (Since(t_run) < 30 && c.Get(big->job_id())->progress().vertices() == 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const auto t0 = Clock::now();
  absl::StatusOr<v1::Job> cancel = c.Cancel(big->job_id());
  ASSERT_TRUE(cancel.ok());
  EXPECT_TRUE(cancel->cancel_requested());
  absl::StatusOr<v1::Job> ended = c.Watch(big->job_id(), nullptr);
  ASSERT_TRUE(ended.ok());
  const double latency = Since(t0);
  EXPECT_EQ(ended->state(), v1::CANCELLED);
  EXPECT_EQ(ended->error().code(), static_cast<int>(grpc::StatusCode::CANCELLED));
  EXPECT_LT(latency, 5.0);
  std::printf("[ info ] cancel latency of a running job: %.3f s\n", latency);
  absl::StatusOr<v1::Job> next_done = c.Watch(next->job_id(), nullptr);
  ASSERT_TRUE(next_done.ok());
  EXPECT_EQ(next_done->state(), v1::SUCCEEDED);
  EXPECT_EQ(c.Fetch(big->job_id()).status().code(), absl::StatusCode::kFailedPrecondition);
}

TEST(ServiceTest, NWorkersRunNJobsAtOnce) {
  ServerProcess server({"--workers=2"});
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  std::vector<std::string> ids;
  for (int i = 0; i < 3; ++i) {
    absl::StatusOr<v1::Job> job = c.Submit(NodeRequest(BigNode()));
    ASSERT_TRUE(job.ok()) << job.status();
    ids.push_back(job->job_id());
  }
  int max_running = 0;
  bool third_waited = false;
  const auto t0 = Clock::now();
  while (Since(t0) < 60 && max_running < 2) {
    int running = 0;
    for (const std::string& id : ids) running += c.Get(id)->state() == v1::RUNNING;
    max_running = std::max(max_running, running);
    if (running == 2) third_waited = c.Get(ids[2])->state() == v1::QUEUED;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(max_running, 2);
  EXPECT_TRUE(third_waited);
  v1::ListJobsRequest running;
  running.add_states(v1::RUNNING);
  EXPECT_LE(c.List(running)->jobs_size(), 2);
  for (const std::string& id : ids) ASSERT_TRUE(c.Cancel(id).ok());
  for (const std::string& id : ids) EXPECT_EQ(c.Watch(id, nullptr)->state(), v1::CANCELLED);
}

TEST(ServiceTest, FullQueueIsResourceExhausted) {
  ServerProcess server({"--workers=1", "--queue-capacity=1"});
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::Job> a = c.Submit(NodeRequest(BigNode()));
  ASSERT_TRUE(a.ok());
  WaitState(c, a->job_id(), v1::RUNNING);
  absl::StatusOr<v1::Job> b = c.Submit(NodeRequest(testing::RandomNodeFile(10, 1)));
  ASSERT_TRUE(b.ok()) << b.status();
  absl::StatusOr<v1::Job> full = c.Submit(NodeRequest(testing::RandomNodeFile(10, 2)), /*attempts=*/1);
  EXPECT_EQ(full.status().code(), absl::StatusCode::kResourceExhausted) << full.status();
  EXPECT_NE(full.status().message().find("queue full"), absl::string_view::npos);
  ASSERT_TRUE(c.Cancel(b->job_id()).ok());  // frees the slot at once
  EXPECT_TRUE(c.Submit(NodeRequest(testing::RandomNodeFile(10, 3))).ok());
  ASSERT_TRUE(c.Cancel(a->job_id()).ok());
}

TEST(ServiceTest, SameRequestIdIsOneJob) {
  ServerProcess server;
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  v1::SubmitJobRequest r = NodeRequest(testing::RandomNodeFile(100, 14));
  r.set_request_id("retry-me-1");
  absl::StatusOr<v1::Job> a = c.Submit(r);
  absl::StatusOr<v1::Job> b = c.Submit(r);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->job_id(), b->job_id());
  c.Watch(a->job_id(), nullptr).IgnoreError();
  absl::StatusOr<v1::Job> after = c.Submit(r);  // also once it has finished
  EXPECT_EQ(after->job_id(), a->job_id());
  EXPECT_EQ(after->state(), v1::SUCCEEDED);
  EXPECT_EQ(c.List(v1::ListJobsRequest())->jobs_size(), 1);
}

TEST(ServiceTest, DeadlineExceededEndsTheJob) {
  ServerProcess server({"--workers=1"});
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  v1::SubmitJobRequest r = NodeRequest(BigNode());
  r.mutable_limits()->mutable_deadline()->set_nanos(300 * 1000 * 1000);
  absl::StatusOr<v1::Job> job = c.Submit(r);
  ASSERT_TRUE(job.ok());
  const auto t0 = Clock::now();
  absl::StatusOr<v1::Job> done = c.Watch(job->job_id(), nullptr);
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->state(), v1::FAILED);
  EXPECT_EQ(done->error().code(), static_cast<int>(grpc::StatusCode::DEADLINE_EXCEEDED))
      << done->error().message();
  EXPECT_LT(Since(t0), 10.0);
}

TEST(ServiceTest, BrokenPlcIsInvalidArgumentNamingTheProblem) {
  ServerProcess server;
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::SubmitJobRequest> r =
      cli::RequestForFile(testing::CorpusPath("g_bad/bad_dangling_index.poly"));
  ASSERT_TRUE(r.ok()) << r.status();
  absl::StatusOr<v1::Job> job = c.Submit(*r);
  ASSERT_TRUE(job.ok());
  absl::StatusOr<v1::Job> done = c.Watch(job->job_id(), nullptr);
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->state(), v1::FAILED);
  EXPECT_EQ(done->error().code(), static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT));
  // The message names the file, the facet and the bad index.
  EXPECT_NE(done->error().message().find("bad_dangling_index.poly"), std::string::npos)
      << done->error().message();
  EXPECT_NE(done->error().message().find("42"), std::string::npos) << done->error().message();
}

// A job that runs out of budget tells how far it got: the mesher's counters
// ride on its status (core/mesh/stats_payload.h) into Job.failure_stats.
TEST(ServiceTest, FailedPlcJobCarriesTheMeshersCounters) {
  ServerProcess server;
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::SubmitJobRequest> r = cli::RequestForFile(testing::CorpusPath("a_convex/cube.poly"));
  ASSERT_TRUE(r.ok()) << r.status();
  r->mutable_parameters()->set_max_volume(1e-6);  // ~10^6 tets wanted
  r->mutable_limits()->set_max_vertices(3000);
  absl::StatusOr<v1::Job> job = c.Submit(*r);
  ASSERT_TRUE(job.ok()) << job.status();
  absl::StatusOr<v1::Job> done = c.Watch(job->job_id(), nullptr);
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->state(), v1::FAILED);
  EXPECT_EQ(done->error().code(), static_cast<int>(grpc::StatusCode::RESOURCE_EXHAUSTED)) << done->error().message();
  std::map<std::string, double> counters;
  for (const v1::Counter& k : done->failure_stats()) counters[k.name()] = k.value();
  ASSERT_TRUE(counters.count("svrc.vertices")) << done->failure_stats_size() << " counters";
  EXPECT_GT(counters["svrc.vertices"], 8);  // more than Ω's corners
  EXPECT_LE(counters["svrc.vertices"], 3000);
  EXPECT_EQ(counters["svrc.vertices_dim0"], 8);  // the cube's corners are in M_Ω
  EXPECT_GT(counters["svrc.insertions"], 0);
  // The same counters after a fetch of the job by id (kept with the job).
  absl::StatusOr<v1::Job> again = c.Get(job->job_id());
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->failure_stats_size(), done->failure_stats_size());
}

TEST(ServiceTest, PlcJobSucceedsWithADecodableMesh) {
  ServerProcess server;
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::SubmitJobRequest> r = cli::RequestForFile(testing::CorpusPath("a_convex/cube.poly"));
  ASSERT_TRUE(r.ok()) << r.status();
  absl::StatusOr<v1::Job> done = c.Watch(c.Submit(*r)->job_id(), nullptr);
  ASSERT_TRUE(done.ok());
  ASSERT_EQ(done->state(), v1::SUCCEEDED) << done->error().message();
  absl::StatusOr<cli::FetchedResult> result = c.Fetch(done->job_id());
  ASSERT_TRUE(result.ok());
  absl::StatusOr<mesh::TetMesh> m = codec::DecodeTetMesh(result->bytes);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(m->tets.size(), done->result().num_tets());
  EXPECT_GT(m->tets.size(), 0u);
}

// Issue #5: byte-identical output across runs and worker counts, for PLCs
// (SVRC refinement with facet meshes, not only a point set's Delaunay): the
// same request meshed twice locally (client/mesh_job.h, the workers' own
// pipeline), then on servers with 1 and 2 workers, each input submitted twice
// at once (with 2 workers two copies run concurrently on different threads).
std::string LocalContainerFor(const v1::SubmitJobRequest& r) {
  absl::StatusOr<plc::InputFormat> format = api::FormatFromProto(r.file().format());
  EXPECT_TRUE(format.ok()) << format.status();
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcBytes(r.file().data(), *format, r.file().name());
  EXPECT_TRUE(plc.ok()) << plc.status();
  absl::StatusOr<cli::MeshOptions> options = api::OptionsFromRequest(r);
  EXPECT_TRUE(options.ok()) << options.status();
  if (!options.ok()) return "";
  absl::StatusOr<mesh::TetMesh> mesh = cli::RunMeshing(*plc, *options, nullptr, nullptr);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  if (!mesh.ok()) return "";
  absl::StatusOr<std::string> bytes = codec::EncodeTetMesh(*mesh, codec::EncodeOptions());
  EXPECT_TRUE(bytes.ok()) << bytes.status();
  return bytes.ok() ? *bytes : "";
}

TEST(ServiceTest, PlcOutputIsByteIdenticalAcrossRunsAndWorkerCounts) {
  std::vector<v1::SubmitJobRequest> requests;
  std::vector<std::string> local;
  // The third job has a max_volume: 18,509 tets refined through the
  // newest-first Skinny₃ buckets (docs/svrc-design.md §8 item 52).
  struct Input {
    const char* file;
    double max_volume;  // 0: none
  };
  for (const Input& in : {Input{"b_internal/box_internal_facet.poly", 0}, Input{"e_spread/tiny_cube_in_box.poly", 0},
                          Input{"b_internal/box_internal_facet.poly", 1e-4}}) {
    const char* file = in.file;
    SCOPED_TRACE(file);
    absl::StatusOr<v1::SubmitJobRequest> r = cli::RequestForFile(testing::CorpusPath(file));
    ASSERT_TRUE(r.ok()) << r.status();
    if (in.max_volume > 0) r->mutable_parameters()->set_max_volume(in.max_volume);
    const std::string a = LocalContainerFor(*r), b = LocalContainerFor(*r);
    ASSERT_FALSE(a.empty());
    EXPECT_TRUE(a == b) << "two local runs differ";
    absl::StatusOr<mesh::TetMesh> mesh = codec::DecodeTetMesh(a);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    EXPECT_GT(mesh->num_tets(), 0u);
    EXPECT_FALSE(mesh->triangles.empty());  // the PLC's facets are in the output
    requests.push_back(*r);
    local.push_back(a);
  }
  for (const char* workers : {"--workers=1", "--workers=2"}) {
    SCOPED_TRACE(workers);
    ServerProcess server({workers});
    ASSERT_TRUE(server.ok());
    RemoteClient c(server.address());
    std::vector<std::pair<size_t, std::string>> jobs;  // (input, job id)
    for (int copy = 0; copy < 2; ++copy) {
      for (size_t i = 0; i < requests.size(); ++i) {
        absl::StatusOr<v1::Job> job = c.Submit(requests[i]);  // a fresh request id each time
        ASSERT_TRUE(job.ok()) << job.status();
        jobs.emplace_back(i, job->job_id());
      }
    }
    std::set<std::string> ids;
    for (const auto& [i, id] : jobs) {
      ids.insert(id);
      absl::StatusOr<v1::Job> done = c.Watch(id, nullptr);
      ASSERT_TRUE(done.ok()) << done.status();
      ASSERT_EQ(done->state(), v1::SUCCEEDED) << done->error().message();
      absl::StatusOr<cli::FetchedResult> result = c.Fetch(id);
      ASSERT_TRUE(result.ok()) << result.status();
      EXPECT_EQ(result->sha256, done->result().sha256());
      EXPECT_TRUE(result->bytes == local[i])
          << "input " << i << " job " << id << ": " << result->bytes.size() << " vs " << local[i].size()
          << " bytes locally";
    }
    EXPECT_EQ(ids.size(), jobs.size());  // six jobs, not deduplicated
  }
}

TEST(ServiceTest, FetchResumesFromAnOffset) {
  ServerProcess server;
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::Job> job = c.Submit(NodeRequest(testing::RandomNodeFile(20000, 15)));
  ASSERT_TRUE(job.ok());
  ASSERT_EQ(c.Watch(job->job_id(), nullptr)->state(), v1::SUCCEEDED);
  absl::StatusOr<cli::FetchedResult> whole = c.Fetch(job->job_id());
  ASSERT_TRUE(whole.ok());
  ASSERT_GT(whole->bytes.size(), 5000u);

  // Read two 1000-byte chunks, drop the stream, resume from what we have.
  std::string part;
  {
    grpc::ClientContext ctx;
    v1::FetchResultRequest req;
    req.set_job_id(job->job_id());
    req.set_max_chunk_bytes(1000);
    auto reader = c.stub().FetchResult(&ctx, req);
    v1::ResultChunk chunk;
    for (int i = 0; i < 2 && reader->Read(&chunk); ++i) {
      EXPECT_EQ(chunk.offset(), part.size());
      EXPECT_EQ(chunk.total_size(), whole->bytes.size());
      EXPECT_EQ(chunk.sha256(), whole->sha256);
      EXPECT_LE(chunk.data().size(), 1000u);
      part += chunk.data();
    }
    ctx.TryCancel();
    reader->Finish().ok();
  }
  ASSERT_EQ(part.size(), 2000u);
  uint64_t total = 0;
  std::string sha;
  ASSERT_TRUE(c.FetchFrom(job->job_id(), part.size(), &part, &total, &sha).ok());
  EXPECT_EQ(part, whole->bytes);
  // Default chunks are at most 1 MiB; past the end is OUT_OF_RANGE.
  std::string tail;
  EXPECT_EQ(c.FetchFrom(job->job_id(), whole->bytes.size() + 1, &tail, &total, &sha).code(),
            absl::StatusCode::kOutOfRange);
  EXPECT_EQ(c.FetchFrom("jnope", 0, &tail, &total, &sha).code(), absl::StatusCode::kNotFound);
  // Delete frees it.
  ASSERT_TRUE(c.Delete(job->job_id()).ok());
  EXPECT_EQ(c.Get(job->job_id()).status().code(), absl::StatusCode::kNotFound);
  EXPECT_FALSE(std::filesystem::exists(server.data_dir() + "/results/" + job->job_id() + ".svrc"));
}

TEST(ServiceTest, FiftyMegabyteUploadArrivesWhole) {
  ServerProcess server;
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  // ~50 MB of points; the vertex limit stops the job right after parsing, which
  // proves every byte arrived (the count is in the message).
  std::string node = testing::RandomNodeFile(1600000, 16);
  ASSERT_GE(node.size(), 50u << 20);
  v1::SubmitJobRequest r = NodeRequest(node);
  r.mutable_limits()->set_max_vertices(1000);
  const auto t0 = Clock::now();
  absl::StatusOr<v1::Job> job = c.Submit(r);
  ASSERT_TRUE(job.ok()) << job.status();
  const double upload_s = Since(t0);
  EXPECT_EQ(job->input_bytes(), node.size());
  absl::StatusOr<v1::Job> done = c.Watch(job->job_id(), nullptr);
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->state(), v1::FAILED);
  EXPECT_EQ(done->error().code(), static_cast<int>(grpc::StatusCode::RESOURCE_EXHAUSTED));
  EXPECT_NE(done->error().message().find("1600000 vertices"), std::string::npos)
      << done->error().message();
  std::printf("[ info ] %zu-byte upload in %.2f s\n", node.size(), upload_s);
}

TEST(ServiceTest, SeveralWatchersAndALateOneAllSeeTheEnd) {
  ServerProcess server;
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::Job> job = c.Submit(NodeRequest(testing::RandomNodeFile(50000, 17)));
  ASSERT_TRUE(job.ok());
  std::vector<std::thread> watchers;
  std::vector<v1::JobState> ends(3, v1::JOB_STATE_UNSPECIFIED);
  for (int i = 0; i < 3; ++i) {
    watchers.emplace_back([&, i] {
      RemoteClient own(server.address());
      absl::StatusOr<v1::Job> done = own.Watch(job->job_id(), nullptr);
      if (done.ok()) ends[i] = done->state();
    });
  }
  for (std::thread& t : watchers) t.join();
  for (v1::JobState s : ends) EXPECT_EQ(s, v1::SUCCEEDED);
  std::vector<v1::JobEvent> late;
  ASSERT_TRUE(c.Watch(job->job_id(), [&](const v1::JobEvent& e) { late.push_back(e); }).ok());
  ASSERT_EQ(late.size(), 1u);  // the current (terminal) state, then the end
  EXPECT_EQ(late[0].job().state(), v1::SUCCEEDED);
  EXPECT_EQ(c.Watch("jmissing", nullptr).status().code(), absl::StatusCode::kNotFound);
}

TEST(ServiceTest, SigtermLetsRunningJobsFinishWithinTheGracePeriod) {
  ServerProcess server({"--workers=1", "--grace-period=60s"});
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::Job> job = c.Submit(NodeRequest(testing::RandomNodeFile(100000, 18)));
  absl::StatusOr<v1::Job> queued = c.Submit(NodeRequest(testing::RandomNodeFile(100, 19)));
  ASSERT_TRUE(job.ok() && queued.ok());
  WaitState(c, job->job_id(), v1::RUNNING);
  std::mutex mu;
  v1::JobState end = v1::JOB_STATE_UNSPECIFIED;
  std::thread watcher([&] {
    absl::StatusOr<v1::Job> done = c.Watch(job->job_id(), nullptr, /*reconnects=*/0);
    std::scoped_lock l(mu);
    if (done.ok()) end = done->state();
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(server.Terminate(60), 0) << server.Log();
  watcher.join();
  std::scoped_lock l(mu);
  EXPECT_EQ(end, v1::SUCCEEDED) << server.Log();  // finished, and the watcher heard it
  // The queued job is not cancelled: it stays queued in the journal for the
  // next start (tests/server/persistence_test.cc runs it there).
  EXPECT_EQ(server.Log().find("job " + queued->job_id() + ": CANCELLED"), std::string::npos)
      << server.Log();
}

TEST(ServiceTest, SigtermStopsJobsStillRunningAfterTheGracePeriod) {
  ServerProcess server({"--workers=1", "--grace-period=200ms"});
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::Job> job = c.Submit(NodeRequest(BigNode()));
  ASSERT_TRUE(job.ok());
  WaitState(c, job->job_id(), v1::RUNNING);
  const auto t0 = Clock::now();
  EXPECT_EQ(server.Terminate(30), 0);
  EXPECT_LT(Since(t0), 10.0);
  // Stopped, and journaled as queued for the next start (not CANCELLED).
  EXPECT_NE(server.Log().find("job " + job->job_id() +
                              ": interrupted by the shutdown; queued for the next start"),
            std::string::npos)
      << server.Log();
}

TEST(ServiceTest, ServerThatCannotListenExitsNonZero) {
  ServerProcess first;
  ASSERT_TRUE(first.ok());
  testing::CommandResult r = testing::RunCommand(
      {SVRC_SERVER_BIN, "--listen=" + first.address(), "--data-dir=" + testing::MakeTempDir("d")});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("cannot listen"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace svrc
