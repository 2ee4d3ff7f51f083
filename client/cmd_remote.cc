// The remote commands: submit, watch, get, cancel, delete, list, health.
// Built only with SVRC_BUILD_SERVICE. --server defaults to localhost:50051.
// Every command takes --tls-ca, --tls-cert, --tls-key, --token-file (or env
// SVRC_TOKEN) for a TLS / authenticated server (docs/security.md).
#include <cstdio>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/cli_util.h"
#include "client/command.h"
#include "client/remote_commands.h"
#include "client/remote_client.h"
#include "core/codec/container.h"
#include "proto/convert.h"

namespace svrc::cli {
namespace {

constexpr char kDefaultServer[] = "localhost:50051";

std::string StatusLine(const v1::Status& s) {
  return absl::StrCat(absl::StatusCodeToString(static_cast<absl::StatusCode>(s.code())), ": ",
                      s.message());
}

// Exit status for a job's terminal state.
int JobExitCode(const v1::Job& job) {
  switch (job.state()) {
    case v1::SUCCEEDED: return kExitOk;
    case v1::CANCELLED: return kExitCancelled;
    default:
      return ExitCodeFor(absl::Status(static_cast<absl::StatusCode>(job.error().code()),
                                      job.error().message()),
                         /*job_outcome=*/true);
  }
}

// Every remote command takes the connection-security flags (docs/security.md).
std::vector<std::string> Remote(std::vector<std::string> flags) {
  flags.insert(flags.end(), {"--tls-ca", "--tls-cert", "--tls-key", "--token-file"});
  return flags;
}

absl::StatusOr<ClientSecurity> SecurityFor(const Args& args) {
  return SecurityFromFlags(args.Get("--tls-ca"), args.Get("--tls-cert"), args.Get("--tls-key"),
                           args.Get("--token-file"));
}

int RpcFail(const absl::Status& s, const std::string& server) {
  return Fail(ExitCodeFor(s, /*job_outcome=*/false),
              absl::StrCat(server, ": ", absl::StatusCodeToString(s.code()), ": ", s.message()));
}

// Fetches a SUCCEEDED job's result and writes it to `out` (.svrc: the raw
// container; other extensions: decoded, then written like `svrc mesh`).
int FetchAndWrite(RemoteClient& client, const v1::Job& job, const std::string& out,
                  const std::string& server) {
  absl::StatusOr<FetchedResult> result = client.Fetch(job.job_id());
  if (!result.ok()) return RpcFail(result.status(), server);
  absl::Status s;
  if (absl::EndsWithIgnoreCase(out, ".svrc")) {
    s = WriteFileBytes(out, result->bytes);
  } else {
    absl::StatusOr<mesh::TetMesh> mesh = codec::DecodeTetMesh(result->bytes);
    if (!mesh.ok()) return Fail(kExitServer, absl::StrCat("cannot decode the result: ", mesh.status().message()));
    s = WriteMeshOutput(*mesh, out, 0);
  }
  if (!s.ok()) return Fail(kExitJobFailed, absl::StrCat("cannot write ", out, ": ", s.message()));
  std::printf("wrote %s (%zu bytes fetched, sha256 %s)\n", out.c_str(), result->bytes.size(),
              result->sha256.c_str());
  mesh::MeshStats stats;
  for (const v1::Counter& c : job.result().stats()) stats.Set(c.name(), c.value());
  WarnMinDihedral(stats);
  return kExitOk;
}

void PrintSummary(const v1::Job& job) {
  if (job.state() == v1::SUCCEEDED) {
    const v1::ResultInfo& r = job.result();
    std::printf("job %s SUCCEEDED: %llu vertices, %llu tets, %llu boundary triangles, "
                "%llu bytes encoded, %.3f s\n",
                job.job_id().c_str(), static_cast<unsigned long long>(r.num_vertices()),
                static_cast<unsigned long long>(r.num_tets()),
                static_cast<unsigned long long>(r.num_triangles()),
                static_cast<unsigned long long>(r.size_bytes()), job.progress().elapsed_seconds());
  } else {
    std::printf("job %s %s\n", job.job_id().c_str(), api::JobStateName(job.state()).c_str());
  }
}

// Watches until the end, then fetches to `out` if given.
int WatchToEnd(RemoteClient& client, const std::string& job_id, const std::string& out,
               bool show_progress, const std::string& server) {
  ProgressPrinter printer(show_progress);
  absl::StatusOr<v1::Job> job = client.Watch(job_id, [&](const v1::JobEvent& e) {
    const v1::Progress& p = e.job().progress();
    printer.Update(api::JobStateName(e.job().state()), p.phase(), p.vertices(), p.queue_size(),
                   p.largest_work_radius(), p.target_radius(), p.elapsed_seconds());
  });
  printer.Done();
  if (!job.ok()) return RpcFail(job.status(), server);
  PrintSummary(*job);
  if (job->state() != v1::SUCCEEDED) {
    return Fail(JobExitCode(*job), absl::StrCat("job ", job_id, " ", api::JobStateName(job->state()),
                                                ": ", StatusLine(job->error())));
  }
  return out.empty() ? kExitOk : FetchAndWrite(client, *job, out, server);
}

// ---- submit ----
int RunSubmit(const std::vector<std::string>& argv);
const Command kSubmit{"submit", RemoteUsage("submit"), &RunSubmit};
const RegisterCommand kRegSubmit{kSubmit};

int RunSubmit(const std::vector<std::string>& argv) {
  std::vector<std::string> values = MeshValueFlags();
  values.insert(values.end(), {"-o", "--server", "--request-id"});
  values = Remote(std::move(values));
  std::vector<std::string> switches = MeshSwitches();
  switches.push_back("--watch");
  absl::StatusOr<Args> args = ParseArgs(argv, values, switches);
  if (!args.ok()) return UsageError(kSubmit, std::string(args.status().message()));
  if (args->positional.size() != 1) return UsageError(kSubmit, "expected one input file");
  absl::StatusOr<MeshOptions> options = MeshOptionsFromArgs(*args);
  if (!options.ok()) return UsageError(kSubmit, std::string(options.status().message()));
  const std::string server = args->Get("--server", kDefaultServer);
  const std::string out = args->Get("-o");
  const bool watch = args->switches.count("--watch") > 0;

  absl::StatusOr<v1::SubmitJobRequest> request = RequestForFile(args->positional[0]);
  if (!request.ok()) return Fail(kExitInvalidInput, std::string(request.status().message()));
  api::OptionsToRequest(*options, &*request);
  request->set_request_id(args->Get("--request-id", NewRequestId()));

  absl::StatusOr<ClientSecurity> security = SecurityFor(*args);
  if (!security.ok()) return RpcFail(security.status(), server);
  RemoteClient client(server, *security);
  absl::StatusOr<v1::Job> job = client.Submit(*std::move(request));
  if (!job.ok()) return RpcFail(job.status(), server);
  if (!watch && out.empty()) {
    std::printf("%s\n", job->job_id().c_str());
    return kExitOk;
  }
  std::fprintf(stderr, "svrc: job %s submitted to %s\n", job->job_id().c_str(), server.c_str());
  return WatchToEnd(client, job->job_id(), out, watch, server);
}

// ---- watch ----
int RunWatch(const std::vector<std::string>& argv);
const Command kWatch{"watch", RemoteUsage("watch"), &RunWatch};
const RegisterCommand kRegWatch{kWatch};

int RunWatch(const std::vector<std::string>& argv) {
  absl::StatusOr<Args> args = ParseArgs(argv, Remote({"-o", "--server"}), {});
  if (!args.ok()) return UsageError(kWatch, std::string(args.status().message()));
  if (args->positional.size() != 1) return UsageError(kWatch, "expected one job id");
  const std::string server = args->Get("--server", kDefaultServer);
  absl::StatusOr<ClientSecurity> security = SecurityFor(*args);
  if (!security.ok()) return RpcFail(security.status(), server);
  RemoteClient client(server, *security);
  return WatchToEnd(client, args->positional[0], args->Get("-o"), true, server);
}

// ---- get ----
int RunGet(const std::vector<std::string>& argv);
const Command kGet{"get", RemoteUsage("get"), &RunGet};
const RegisterCommand kRegGet{kGet};

int RunGet(const std::vector<std::string>& argv) {
  absl::StatusOr<Args> args = ParseArgs(argv, Remote({"-o", "--server"}), {});
  if (!args.ok()) return UsageError(kGet, std::string(args.status().message()));
  if (args->positional.size() != 1) return UsageError(kGet, "expected one job id");
  const std::string server = args->Get("--server", kDefaultServer);
  absl::StatusOr<ClientSecurity> security = SecurityFor(*args);
  if (!security.ok()) return RpcFail(security.status(), server);
  RemoteClient client(server, *security);
  absl::StatusOr<v1::Job> job = client.Get(args->positional[0]);
  if (!job.ok()) return RpcFail(job.status(), server);
  const std::string out = args->Get("-o");
  if (out.empty()) {
    const v1::Progress& p = job->progress();
    std::printf("job %s %s phase=%s vertices=%llu queue=%llu elapsed=%.3fs input=%s\n",
                job->job_id().c_str(), api::JobStateName(job->state()).c_str(), p.phase().c_str(),
                static_cast<unsigned long long>(p.vertices()),
                static_cast<unsigned long long>(p.queue_size()), p.elapsed_seconds(),
                job->input_name().c_str());
    if (job->has_error()) std::printf("error %s\n", StatusLine(job->error()).c_str());
    for (const v1::Counter& c : job->failure_stats()) std::printf("  %-34s %.10g\n", c.name().c_str(), c.value());
    if (job->state() == v1::SUCCEEDED) PrintSummary(*job);
    return kExitOk;
  }
  if (!api::IsTerminal(job->state())) {
    return Fail(kExitServer, absl::StrCat("job ", job->job_id(), " is ",
                                          api::JobStateName(job->state()),
                                          "; no result yet (svrc watch ", job->job_id(), ")"));
  }
  if (job->state() != v1::SUCCEEDED) {
    return Fail(JobExitCode(*job), absl::StrCat("job ", job->job_id(), " ",
                                                api::JobStateName(job->state()), ": ",
                                                StatusLine(job->error())));
  }
  return FetchAndWrite(client, *job, out, server);
}

// ---- cancel ----
int RunCancel(const std::vector<std::string>& argv);
const Command kCancel{"cancel", RemoteUsage("cancel"), &RunCancel};
const RegisterCommand kRegCancel{kCancel};

int RunCancel(const std::vector<std::string>& argv) {
  absl::StatusOr<Args> args = ParseArgs(argv, Remote({"--server"}), {});
  if (!args.ok()) return UsageError(kCancel, std::string(args.status().message()));
  if (args->positional.size() != 1) return UsageError(kCancel, "expected one job id");
  const std::string server = args->Get("--server", kDefaultServer);
  absl::StatusOr<ClientSecurity> security = SecurityFor(*args);
  if (!security.ok()) return RpcFail(security.status(), server);
  RemoteClient client(server, *security);
  absl::StatusOr<v1::Job> job = client.Cancel(args->positional[0]);
  if (!job.ok()) return RpcFail(job.status(), server);
  std::printf("job %s %s%s\n", job->job_id().c_str(), api::JobStateName(job->state()).c_str(),
              job->state() == v1::CANCELLED || api::IsTerminal(job->state())
                  ? ""
                  : " (cancel requested)");
  return kExitOk;
}

// ---- delete ----
int RunDelete(const std::vector<std::string>& argv);
const Command kDelete{"delete", RemoteUsage("delete"), &RunDelete};
const RegisterCommand kRegDelete{kDelete};

int RunDelete(const std::vector<std::string>& argv) {
  absl::StatusOr<Args> args = ParseArgs(argv, Remote({"--server"}), {});
  if (!args.ok()) return UsageError(kDelete, std::string(args.status().message()));
  if (args->positional.size() != 1) return UsageError(kDelete, "expected one job id");
  const std::string server = args->Get("--server", kDefaultServer);
  absl::StatusOr<ClientSecurity> security = SecurityFor(*args);
  if (!security.ok()) return RpcFail(security.status(), server);
  RemoteClient client(server, *security);
  if (absl::Status s = client.Delete(args->positional[0]); !s.ok()) return RpcFail(s, server);
  std::printf("job %s deleted\n", args->positional[0].c_str());
  return kExitOk;
}

// ---- list ----
int RunList(const std::vector<std::string>& argv);
const Command kList{"list", RemoteUsage("list"), &RunList};
const RegisterCommand kRegList{kList};

int RunList(const std::vector<std::string>& argv) {
  absl::StatusOr<Args> args = ParseArgs(argv, Remote({"--server", "--state", "--page-size"}), {});
  if (!args.ok()) return UsageError(kList, std::string(args.status().message()));
  if (!args->positional.empty()) return UsageError(kList, "no positional arguments");
  const std::string server = args->Get("--server", kDefaultServer);
  v1::ListJobsRequest request;
  if (args->Has("--state")) {
    for (absl::string_view name : absl::StrSplit(args->Get("--state"), ',', absl::SkipEmpty())) {
      v1::JobState state;
      if (!v1::JobState_Parse(std::string(name), &state) || state == v1::JOB_STATE_UNSPECIFIED) {
        return UsageError(kList, absl::StrCat("unknown state '", name, "'"));
      }
      request.add_states(state);
    }
  }
  int page_size = 100;
  if (args->Has("--page-size") && (!absl::SimpleAtoi(args->Get("--page-size"), &page_size) || page_size < 1)) {
    return UsageError(kList, "--page-size must be a positive integer");
  }
  request.set_page_size(page_size);
  absl::StatusOr<ClientSecurity> security = SecurityFor(*args);
  if (!security.ok()) return RpcFail(security.status(), server);
  RemoteClient client(server, *security);
  std::printf("%-18s %-10s %-10s %10s  %s\n", "JOB", "STATE", "PHASE", "VERTICES", "INPUT");
  do {
    absl::StatusOr<v1::ListJobsResponse> page = client.List(request);
    if (!page.ok()) return RpcFail(page.status(), server);
    for (const v1::Job& job : page->jobs()) {
      std::printf("%-18s %-10s %-10s %10llu  %s\n", job.job_id().c_str(),
                  api::JobStateName(job.state()).c_str(), job.progress().phase().c_str(),
                  static_cast<unsigned long long>(job.progress().vertices()),
                  job.input_name().c_str());
    }
    request.set_page_token(page->next_page_token());
  } while (!request.page_token().empty());
  return kExitOk;
}

// ---- health ----
int RunHealth(const std::vector<std::string>& argv);
const Command kHealth{"health", RemoteUsage("health"), &RunHealth};
const RegisterCommand kRegHealth{kHealth};

int RunHealth(const std::vector<std::string>& argv) {
  absl::StatusOr<Args> args = ParseArgs(argv, Remote({"--server"}), {});
  if (!args.ok()) return UsageError(kHealth, std::string(args.status().message()));
  const std::string server = args->Get("--server", kDefaultServer);
  absl::StatusOr<ClientSecurity> security = SecurityFor(*args);
  if (!security.ok()) return RpcFail(security.status(), server);
  RemoteClient client(server, *security);
  absl::StatusOr<bool> serving = client.Serving();
  if (!serving.ok()) return RpcFail(serving.status(), server);
  std::printf("%s\n", *serving ? "SERVING" : "NOT_SERVING");
  return *serving ? kExitOk : Fail(kExitServer, absl::StrCat(server, " is not serving"));
}

}  // namespace
}  // namespace svrc::cli
