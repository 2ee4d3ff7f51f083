#include "server/watch_stream.h"

#include <utility>

#include "proto/convert.h"

namespace svrc::server {

WatchStream::Action WatchStream::Offer(const v1::JobEvent& event) {
  std::scoped_lock lock(mu_);
  if (finished_ || sent_terminal_) return Action::kNone;
  if (api::IsTerminal(event.job().state())) sent_terminal_ = true;
  if (writing_) {
    pending_ = event;  // replaces an older unsent snapshot
    return Action::kNone;
  }
  in_flight_ = event;
  writing_ = true;
  return Action::kWrite;
}

WatchStream::Action WatchStream::WriteDone() {
  std::scoped_lock lock(mu_);
  writing_ = false;
  if (finished_) return Action::kNone;  // closed meanwhile: nothing more is written
  if (pending_) {
    in_flight_ = std::move(*pending_);
    pending_.reset();
    writing_ = true;
    return Action::kWrite;
  }
  if (sent_terminal_) {
    finished_ = true;
    return Action::kFinish;
  }
  return Action::kNone;
}

bool WatchStream::Close() {
  std::scoped_lock lock(mu_);
  if (finished_) return false;
  finished_ = true;
  pending_.reset();
  return true;
}

}  // namespace svrc::server
