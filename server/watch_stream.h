// The flow control of one WatchJob stream, without gRPC: server/service.cc's
// WatchReactor drives it from gRPC and worker threads, the unit tests from
// plain threads (so the TSan stage of scripts/test.sh checks it). Every
// snapshot of the job is offered; at most one write is in flight; a newer
// snapshot replaces an unsent one (each carries the whole job, so the
// latest wins: slow readers get coalesced progress); the stream finishes
// after the terminal snapshot is written; a closed stream writes nothing more.
// DESIGN.md "Data flow", docs/service.md (WatchJob).
#pragma once

#include <mutex>
#include <optional>

#include "svrc/v1/service.pb.h"

namespace svrc::server {

class WatchStream {
 public:
  enum class Action {
    kNone,    // nothing to do
    kWrite,   // start writing in_flight()
    kFinish,  // the terminal snapshot was written: finish the call (OK)
  };

  // A new snapshot of the job (the manager's listener, any thread).
  Action Offer(const v1::JobEvent& event);
  // The write of in_flight() completed successfully. kWrite: write
  // in_flight() again (it now holds the newest unsent snapshot). The decision
  // is taken under the same lock that Offer takes, so exactly one of the two
  // starts the next write.
  Action WriteDone();
  // The call ends early (cancelled, broken, refused). True the first time
  // nothing has finished the call yet: the caller finishes it with its status.
  bool Close();

  // What to write after a kWrite. Changed only by Offer/WriteDone while no
  // write is in flight, so it is stable from kWrite until WriteDone.
  const v1::JobEvent& in_flight() const { return in_flight_; }

 private:
  // std::mutex (intercepted by TSan, unlike Debian's absl::Mutex). Guards
  // pending_, writing_, sent_terminal_ and finished_; in_flight_ is written
  // under it and read by the transport only between kWrite and WriteDone.
  std::mutex mu_;
  v1::JobEvent in_flight_;
  std::optional<v1::JobEvent> pending_;
  bool writing_ = false;
  bool sent_terminal_ = false;  // the terminal snapshot is in flight or pending
  bool finished_ = false;       // kFinish returned or Close() returned true
};

}  // namespace svrc::server
