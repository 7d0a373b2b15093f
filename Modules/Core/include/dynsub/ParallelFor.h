#pragma once
// Independent per-item work on the machine's cores.
#include <algorithm>
#include <exception>
#include <future>
#include <thread>
#include <vector>

#include <Eigen/Core>

namespace dynsub {

// body(i) for i in [0, count): one contiguous chunk per thread, on at most
// `threadsWorthIt` threads (the caller's measure of its work: handing a chunk
// to another thread costs tens of microseconds, a few closest-point queries'
// worth), at most one per hardware thread; on this thread alone when that is
// 1 or less. Each item must be independent of the others, so that results do
// not depend on the thread count.
// DynSub's own helper threads, which sleep between calls, instead of
// OpenMP: libgomp's workers spin-wait between parallel loops, which took a
// third of the CPU time of a segmentation whose loops are mostly small.
// The threads `items` independent pieces of per-point work (a closest-point
// query, a point's stiffness) are worth: one per 128, so none below 256.
inline Eigen::Index threadsWorth(Eigen::Index items) { return items / 128; }

// The hardware threads, asked once: glibc answers by reading
// /sys/devices/system/cpu/online each time (6 us here), which the implicit
// step, about a millisecond, would otherwise pay three times.
inline Eigen::Index hardwareThreads() {
  static const Eigen::Index threads = std::max(1u, std::thread::hardware_concurrency());
  return threads;
}

namespace detail {

// The process's helper threads, one per hardware thread beyond the first,
// started at the first call and kept, waiting, until the process ends.
// startOnHelper hands run(context, part) to an idle one and returns its
// number, or -1 when every one is busy (with another caller's work);
// waitForHelper(number) returns once that work has ended and frees the
// helper. `run` must not throw.
int startOnHelper(void (*run)(void* context, Eigen::Index part), void* context, Eigen::Index part);
void waitForHelper(int helper);

}  // namespace detail

// An exception thrown by `body` is rethrown here once every thread has
// ended: the first chunk's that threw, so the same one whatever the timing.
// Chunks go to the waiting helper threads (detail::startOnHelper), or,
// when another caller has them busy, to threads started for the call:
// starting a thread took 50-100 us on this virtual machine, and the implicit
// step, about a millisecond, split its solves in two twice per step.
template <class Body>
void parallelFor(Eigen::Index count, Eigen::Index threadsWorthIt, const Body& body) {
  const Eigen::Index threads = std::min<Eigen::Index>({hardwareThreads(), count, threadsWorthIt});
  if (threads < 2) {
    for (Eigen::Index i = 0; i < count; ++i) body(i);
    return;
  }
  const Eigen::Index chunk = (count + threads - 1) / threads;
  std::vector<std::exception_ptr> failed(threads);
  auto run = [&](Eigen::Index t) {
    try {
      for (Eigen::Index i = t * chunk; i < std::min(count, (t + 1) * chunk); ++i) body(i);
    } catch (...) {
      failed[t] = std::current_exception();
    }
  };
  using Run = decltype(run);
  const auto onHelper = [](void* context, Eigen::Index t) { (*static_cast<Run*>(context))(t); };
  std::vector<int> helpers;
  std::vector<std::thread> workers;
  helpers.reserve(threads);
  workers.reserve(threads);
  for (Eigen::Index t = 1; t < threads; ++t) {
    const int helper = detail::startOnHelper(onHelper, &run, t);
    if (helper >= 0) {
      helpers.push_back(helper);
      continue;
    }
    // Nothing may leave this loop by an exception while helpers run
    // `run`, which lives on this frame.
    try {
      workers.emplace_back([&run, t] { run(t); });
    } catch (...) {
      run(t);  // no thread to be had (system_error, bad_alloc): this one does the chunk
    }
  }
  run(0);
  for (int helper : helpers) detail::waitForHelper(helper);
  for (std::thread& w : workers) w.join();
  for (const std::exception_ptr& failure : failed)
    if (failure) std::rethrow_exception(failure);
}

// first() and second() at once, on two threads where there are two cores
// (one after the other otherwise): the two halves of a split piece of work.
template <class First, class Second>
void bothAtOnce(const First& first, const Second& second) {
  parallelFor(2, 2, [&](Eigen::Index half) { half == 0 ? first() : second(); });
}

// background() on a second thread while foreground() runs on this one; an
// exception from background() is rethrown before one from foreground(), as
// when it ran first. For output written meanwhile, where this thread keeps
// what must stay on it (adding outputs to a set, rendering).
template <class Background, class Foreground>
void alongside(const Background& background, const Foreground& foreground) {
  std::future<void> done = std::async(std::launch::async, [&] { background(); });
  try {
    foreground();
  } catch (...) {
    done.get();  // its error, if any, comes first
    throw;
  }
  done.get();
}

}  // namespace dynsub
