#include "dynsub/ResidentHeap.h"

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace {

// The heap's extent in /proc/self/smaps (advice splits it into several
// [heap] mappings) and whether the kernel may back its largest mapping with
// huge pages (THPeligible).
struct HeapMapping {
  std::uintptr_t begin = UINTPTR_MAX, end = 0;
  std::uintptr_t largest = 0;
  int hugePageEligible = -1;
};

// Whether the kernel may back the mapping that holds `address` with huge
// pages (its THPeligible in /proc/self/smaps); -1 when no mapping holds it.
int hugePageEligibleAt(std::uintptr_t address) {
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = address >= begin && address < end;
    } else if (inside && line.rfind("THPeligible:", 0) == 0) {
      return std::stoi(line.substr(12));
    }
  }
  return -1;
}

HeapMapping heapMapping() {
  HeapMapping heap;
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inHeap = false, inLargest = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {  // a mapping's first line
      inHeap = line.find("[heap]") != std::string::npos;
      inLargest = inHeap && end - begin > heap.largest;
      if (!inHeap) continue;
      heap.begin = std::min(heap.begin, begin);
      heap.end = std::max(heap.end, end);
      if (inLargest) heap.largest = end - begin;
    } else if (inLargest && line.rfind("THPeligible:", 0) == 0) {
      heap.hugePageEligible = std::stoi(line.substr(12));
    }
  }
  return heap;
}

std::string kernelHugePageMode() {
  std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(file, modes);
  const auto open = modes.find('['), close = modes.find(']');
  return open == std::string::npos || close == std::string::npos ? "" : modes.substr(open + 1, close - open - 1);
}

TEST(ResidentHeap, LargeBlocksComeFromAHeapOfHugePages) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's allocator replaces glibc's";
#endif
  dynsub::useResidentHeap();
  // A 24 MB block is above glibc's default mmap threshold (128 kB, growing to
  // at most 32 MB), so without the policy it would get a mapping of its own.
  void* volatile block = std::malloc(24 << 20);
  ASSERT_NE(block, nullptr);
  const HeapMapping heap = heapMapping();
  const auto address = reinterpret_cast<std::uintptr_t>(block);
  EXPECT_GE(address, heap.begin);
  EXPECT_LT(address, heap.end);
  // At least the 512 MB of address space reserved (untouched, so not resident).
  EXPECT_GE(heap.end - heap.begin, std::uintptr_t(512) << 20);
  // Freed, it stays: the heap's top is not trimmed.
  const auto top = reinterpret_cast<std::uintptr_t>(sbrk(0));
  std::free(block);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(sbrk(0)), top);
  // The kernel may use huge pages for it unless they are off altogether.
  const std::string mode = kernelHugePageMode();
  if (mode == "madvise" || mode == "always") {
    EXPECT_EQ(heap.hugePageEligible, 1) << "kernel mode " << mode;
  }
}

// A thread's own arena (glibc maps one per thread that allocates while
// another holds the main heap) is eligible for huge pages once the thread
// has called useResidentArena, and not before (the kernel's madvise mode).
TEST(ResidentHeap, AThreadsArenaGetsHugePages) {
  if (!dynsub::kGlibcMalloc) GTEST_SKIP() << "the sanitizer's allocator replaces glibc's";
  if (kernelHugePageMode() != "madvise") GTEST_SKIP() << "the kernel's huge pages are not in madvise mode";
  dynsub::useResidentHeap();
  int before = -2, after = -2;
  std::thread([&] {
    void* volatile first = std::malloc(1 << 20);
    before = hugePageEligibleAt(reinterpret_cast<std::uintptr_t>(first));
    dynsub::useResidentArena();
    void* volatile second = std::malloc(1 << 20);
    after = hugePageEligibleAt(reinterpret_cast<std::uintptr_t>(second));
    std::free(first);
    std::free(second);
  }).join();
  EXPECT_EQ(before, 0) << "the thread's arena was eligible before the advice";
  EXPECT_EQ(after, 1);
}

}  // namespace
