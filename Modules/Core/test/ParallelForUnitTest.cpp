// parallelFor hands chunks to the process's waiting helper threads, or to
// threads of its own when another caller has the helpers busy. Every item
// runs once whoever runs it: from one caller, from several at once, and from
// within another parallelFor's item, many times over (a helper handed back
// too early, or never freed, would lose items or hang).
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "dynsub/ParallelFor.h"

namespace dynsub {
namespace {

// Each item of [0, count) adds its number once: the sum tells a lost or
// repeated item.
long long sumOfItems(Eigen::Index count) {
  std::atomic<long long> sum{0};
  parallelFor(count, 8, [&](Eigen::Index i) { sum += i; });
  return sum.load();
}

long long expectedSum(Eigen::Index count) { return static_cast<long long>(count) * (count - 1) / 2; }

TEST(ParallelFor, EveryItemRunsOnceCallAfterCall) {
  for (int call = 0; call < 2000; ++call) ASSERT_EQ(sumOfItems(100 + call % 7), expectedSum(100 + call % 7));
}

TEST(ParallelFor, CallersAtOnceShareTheHelpersOrStartThreads) {
  std::atomic<int> wrong{0};
  std::vector<std::thread> callers;
  for (int c = 0; c < 4; ++c)
    callers.emplace_back([&] {
      for (int call = 0; call < 500; ++call)
        if (sumOfItems(64) != expectedSum(64)) ++wrong;
    });
  for (std::thread& caller : callers) caller.join();
  EXPECT_EQ(wrong.load(), 0);
}

TEST(ParallelFor, AParallelForWithinAnItemRunsEveryItemToo) {
  std::atomic<long long> sum{0};
  parallelFor(16, 2, [&](Eigen::Index outer) { sum += sumOfItems(50) + outer; });
  EXPECT_EQ(sum.load(), 16 * expectedSum(50) + expectedSum(16));
}

}  // namespace
}  // namespace dynsub
