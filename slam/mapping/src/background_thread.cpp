#include "background_thread.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

#include <tbb/info.h>

namespace featsense::mapping {
namespace {

int arena_threads() { return std::max(1, tbb::info::default_concurrency() - 1); }

}  // namespace

BackgroundThread::BackgroundThread(int nice_increment) : arena_(arena_threads()) {
  // On Linux the nice value belongs to each thread: PRIO_PROCESS with a thread id sets it for
  // that thread only (setpriority(2), NOTES).
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int current = getpriority(PRIO_PROCESS, tid);
  if (errno != 0) return;
  setpriority(PRIO_PROCESS, tid, std::min(19, current + nice_increment));
}

}  // namespace featsense::mapping
