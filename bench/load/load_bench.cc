// Load test of a running svrc-server (not in CI): C concurrent clients submit
// J small point-set jobs in total, each watched to the end and fetched; then
// K cancels of running large jobs. Prints jobs/s, p50/p99 submit-to-result
// latency, lost and duplicated jobs, cancel latencies.
//   svrc_load_bench --server HOST:PORT [--clients 8] [--jobs 200]
//                   [--points 200] [--cancels 3] [--cancel-points 300000]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/synchronization/mutex.h"
#include "client/remote_client.h"

namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string NodeFile(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::string out = absl::StrCat(n, " 3 0 0\n");
  for (int i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng), z = u(rng);
    absl::StrAppend(&out, absl::StrFormat("%d %.6f %.6f %.6f\n", i + 1, x, y, z));
  }
  return out;
}

svrc::v1::SubmitJobRequest Request(const std::string& node) {
  svrc::v1::SubmitJobRequest r;
  r.mutable_file()->set_format(svrc::v1::NODE);
  r.mutable_file()->set_name("load.node");
  r.mutable_file()->set_data(node);
  return r;
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5));
  return v[i];
}

}  // namespace

int main(int argc, char** argv) {
  std::string server;
  int clients = 8, jobs = 200, points = 200, cancels = 3, cancel_points = 300000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    int* target = flag == "--clients" ? &clients : flag == "--jobs" ? &jobs
                : flag == "--points" ? &points : flag == "--cancels" ? &cancels
                : flag == "--cancel-points" ? &cancel_points : nullptr;
    if (flag == "--server") server = value;
    else if (target == nullptr || !absl::SimpleAtoi(value, target)) {
      std::fprintf(stderr, "bad argument %s\n", flag.c_str());
      return 2;
    }
  }
  if (server.empty()) {
    std::fprintf(stderr, "usage: svrc_load_bench --server HOST:PORT [...]\n");
    return 2;
  }

  absl::Mutex mu;
  std::vector<double> latencies;
  std::multiset<std::string> ids;
  std::atomic<int> next{0}, failed{0}, wrong{0};
  const auto t0 = Clock::now();
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      svrc::cli::RemoteClient client(server);
      for (int j; (j = next.fetch_add(1)) < jobs;) {
        const std::string node = NodeFile(points, 1000 + j);
        const auto start = Clock::now();
        absl::StatusOr<svrc::v1::Job> job = client.Submit(Request(node));
        if (!job.ok()) {
          failed.fetch_add(1);
          std::fprintf(stderr, "submit %d: %s\n", j, job.status().ToString().c_str());
          continue;
        }
        absl::StatusOr<svrc::v1::Job> done = client.Watch(job->job_id(), nullptr);
        absl::StatusOr<svrc::cli::FetchedResult> result =
            done.ok() && done->state() == svrc::v1::SUCCEEDED
                ? client.Fetch(job->job_id())
                : absl::StatusOr<svrc::cli::FetchedResult>(absl::InternalError("job did not succeed"));
        const double latency = Since(start);
        if (!result.ok()) {
          failed.fetch_add(1);
          std::fprintf(stderr, "job %s: %s\n", job->job_id().c_str(), result.status().ToString().c_str());
          continue;
        }
        if (done->result().num_vertices() != static_cast<uint64_t>(points)) wrong.fetch_add(1);
        absl::MutexLock lock(&mu);
        latencies.push_back(latency);
        ids.insert(job->job_id());
      }
    });
  }
  for (std::thread& t : threads) t.join();
  const double wall = Since(t0);

  // Every job the server knows about, once.
  svrc::cli::RemoteClient client(server);
  svrc::v1::ListJobsRequest list;
  list.set_page_size(1000);
  size_t listed = 0;
  std::set<std::string> listed_ids;
  do {
    absl::StatusOr<svrc::v1::ListJobsResponse> page = client.List(list);
    if (!page.ok()) break;
    for (const auto& j : page->jobs()) {
      ++listed;
      listed_ids.insert(j.job_id());
    }
    list.set_page_token(page->next_page_token());
  } while (!list.page_token().empty());
  size_t duplicated = ids.size() - std::set<std::string>(ids.begin(), ids.end()).size();
  size_t lost = 0;
  for (const std::string& id : ids) lost += listed_ids.count(id) == 0;

  std::printf("jobs: %d submitted by %d clients, %zu succeeded and fetched, %d failed, "
              "%d wrong vertex count\n", jobs, clients, latencies.size(), failed.load(), wrong.load());
  std::printf("lost: %zu (succeeded but not listed), duplicated ids: %zu, listed on server: %zu\n",
              lost, duplicated, listed);
  std::printf("throughput: %.1f jobs/s (%.2f s wall)\n", latencies.size() / wall, wall);
  std::printf("submit-to-result latency: p50 %.1f ms, p99 %.1f ms, max %.1f ms\n",
              1e3 * Percentile(latencies, 0.5), 1e3 * Percentile(latencies, 0.99),
              1e3 * Percentile(latencies, 1.0));

  std::vector<double> cancel_latency;
  const std::string big = cancels > 0 ? NodeFile(cancel_points, 7) : "";
  for (int k = 0; k < cancels; ++k) {
    absl::StatusOr<svrc::v1::Job> job = client.Submit(Request(big));
    if (!job.ok()) continue;
    const auto tw = Clock::now();
    while (Since(tw) < 120) {
      absl::StatusOr<svrc::v1::Job> j = client.Get(job->job_id());
      if (j.ok() && j->state() == svrc::v1::RUNNING && j->progress().vertices() > 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    const auto tc = Clock::now();
    if (!client.Cancel(job->job_id()).ok()) continue;
    absl::StatusOr<svrc::v1::Job> done = client.Watch(job->job_id(), nullptr);
    if (done.ok() && done->state() == svrc::v1::CANCELLED) cancel_latency.push_back(Since(tc));
  }
  if (!cancel_latency.empty()) {
    std::printf("cancel latency (RUNNING %d-point job → CANCELLED), %zu runs: max %.3f s, p50 %.3f s\n",
                cancel_points, cancel_latency.size(), Percentile(cancel_latency, 1.0),
                Percentile(cancel_latency, 0.5));
  }
  return (failed.load() == 0 && lost == 0 && duplicated == 0 && wrong.load() == 0) ? 0 : 1;
}
