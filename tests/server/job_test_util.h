// Proto-level helpers shared by the server test suites (job manager, service,
// persistence, security): building a .node submit request and waiting for a
// job to reach a terminal state through anything with Get(job_id).
#pragma once

#include <chrono>
#include <string>
#include <thread>

#include "absl/status/statusor.h"
#include "gtest/gtest.h"
#include "svrc/v1/service.pb.h"

namespace svrc::testing {

// A SubmitJobRequest carrying `node` as a TetGen .node file named `name`.
inline v1::SubmitJobRequest NodeRequest(const std::string& node,
                                        const std::string& request_id = "",
                                        const std::string& name = "points.node") {
  v1::SubmitJobRequest r;
  r.set_request_id(request_id);
  r.mutable_file()->set_format(v1::NODE);
  r.mutable_file()->set_name(name);
  r.mutable_file()->set_data(node);
  return r;
}

inline bool IsTerminal(v1::JobState s) {
  return s == v1::SUCCEEDED || s == v1::FAILED || s == v1::CANCELLED;
}

// Polls `source.Get(id)` (a JobManager or a RemoteClient) until the job is
// SUCCEEDED, FAILED or CANCELLED; fails the test after `timeout_s`.
template <typename JobSource>
v1::Job WaitTerminal(JobSource& source, const std::string& id, double timeout_s = 120) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  absl::StatusOr<v1::Job> job;
  while (std::chrono::steady_clock::now() < end) {
    job = source.Get(id);
    if (job.ok() && IsTerminal(job->state())) return *job;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ADD_FAILURE() << "job " << id << " did not finish: "
                << (job.ok() ? v1::JobState_Name(job->state()) : job.status().ToString());
  return job.ok() ? *job : v1::Job();
}

}  // namespace svrc::testing
