// Per-job heap accounting for the job service's memory budget
// (--max-job-memory-mb): while a worker thread runs a job, every global
// operator new/delete on that thread adds/subtracts the block's usable size
// to the job's counter. The job manager compares it with the budget at each
// progress report and janitor tick and cancels the job through its
// core::CancelToken when it is over (the core already polls the token), so
// no core code changes. docs/service.md "Limits" has the caveats.
#pragma once

#include <atomic>
#include <cstdint>

namespace svrc::server {

struct JobMemory {
  std::atomic<int64_t> bytes{0};  // allocated minus freed on the job's thread
  std::atomic<int64_t> peak{0};
};

// Binds the calling thread's allocations to `memory` (nullptr: unbind).
void BindThreadMemory(JobMemory* memory);

// False in sanitizer builds, where the sanitizer owns operator new and
// nothing is counted.
bool MemoryAccountingActive();

}  // namespace svrc::server
