#include "dynsub/ParallelFor.h"

#include <atomic>
#include <condition_variable>
#include <mutex>


namespace dynsub::detail {
namespace {

// One helper thread and the work handed to it.
struct Helper {
  std::atomic<bool> claimed{false};  // by a caller, from startOnHelper to waitForHelper
  std::mutex mutex;
  std::condition_variable wake, done;
  void (*run)(void*, Eigen::Index) = nullptr;
  void* context = nullptr;
  Eigen::Index part = 0;
  bool hasWork = false, finished = false;
};

void serve(Helper* helper) {
  std::unique_lock<std::mutex> lock(helper->mutex);
  for (;;) {
    helper->wake.wait(lock, [helper] { return helper->hasWork; });
    helper->hasWork = false;
    lock.unlock();
    helper->run(helper->context, helper->part);
    lock.lock();
    helper->finished = true;
    helper->done.notify_one();
  }
}

struct Helpers {
  Helper* helpers = nullptr;
  int count = 0;
};

// Never freed, and their threads detached: they wait until the process
// ends, and nothing at exit may wait for them or destroy what they wait on.
const Helpers& helpers() {
  static const Helpers started = [] {
    Helpers h;
    const int wanted = static_cast<int>(hardwareThreads()) - 1;
    if (wanted < 1) return h;
    h.helpers = new Helper[wanted];
    for (; h.count < wanted; ++h.count) {
      try {
        std::thread(serve, &h.helpers[h.count]).detach();
      } catch (...) {
        break;  // fewer helpers; parallelFor starts threads of its own for the rest
      }
    }
    return h;
  }();
  return started;
}

}  // namespace

int startOnHelper(void (*run)(void*, Eigen::Index), void* context, Eigen::Index part) {
  const Helpers& h = helpers();
  for (int i = 0; i < h.count; ++i) {
    Helper& helper = h.helpers[i];
    bool idle = false;
    if (!helper.claimed.compare_exchange_strong(idle, true)) continue;
    {
      const std::lock_guard<std::mutex> lock(helper.mutex);
      helper.run = run;
      helper.context = context;
      helper.part = part;
      helper.finished = false;
      helper.hasWork = true;
    }
    helper.wake.notify_one();
    return i;
  }
  return -1;
}

void waitForHelper(int i) {
  Helper& helper = helpers().helpers[i];
  {
    std::unique_lock<std::mutex> lock(helper.mutex);
    helper.done.wait(lock, [&helper] { return helper.finished; });
  }
  helper.claimed.store(false);
}

}  // namespace dynsub::detail
