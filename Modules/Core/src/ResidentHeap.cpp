#include "dynsub/ResidentHeap.h"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <vector>

// The main heap (sbrk's) lies between the end of the program's data, which
// the linker marks `end`, and the break.
// NB: in a shared library (DynSub's drawing library carries its own copy of
// this module) `end` is the library's own; there useResidentHeap is never
// called, so useResidentArena does nothing.
extern "C" char end;

namespace dynsub {

namespace {

bool residentHeapUsed = false;

}  // namespace

void useResidentHeap() {
  constexpr int kMiB = 1 << 20;
  // 32 MB is the most glibc takes for the threshold of blocks that get their
  // own mapping (and so a page fault per 4 kB at every reuse).
  mallopt(M_MMAP_THRESHOLD, 32 * kMiB);
  mallopt(M_TRIM_THRESHOLD, 1024 * kMiB);
  // NB: threads keep arenas of their own (useResidentArena gives them huge
  // pages). One arena for all
  // (M_ARENA_MAX 1) saved the kitten's fit 5000 page faults but made
  // `evaluate --jobs 2`, two segmentations allocating at once, 12 % slower
  // (89 against 80 s on the tuning split).

  // Grow the heap once by 512 MB of address space, then mark it for huge pages.
  const auto top = [] { return reinterpret_cast<std::uintptr_t>(sbrk(0)); };
  const std::uintptr_t before = top();
  residentHeapUsed = true;
  mallopt(M_TOP_PAD, 512 * kMiB);
  // volatile: a malloc freed unused may otherwise be left out by the compiler.
  void* volatile block = std::malloc(16 * kMiB);
  std::free(block);
  mallopt(M_TOP_PAD, 64 * kMiB);
  const std::uintptr_t after = top();
  constexpr std::uintptr_t kHugePage = 2 * kMiB;
  const std::uintptr_t from = (before + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t to = after & ~(kHugePage - 1);
  // The heap did not grow by sbrk (another allocator, or no room): nothing to mark.
  // A kernel without transparent huge pages refuses the advice; 4 kB pages then.
  if (to > from) madvise(reinterpret_cast<void*>(from), to - from, MADV_HUGEPAGE);
}

void useResidentArena() noexcept {
  if (!kGlibcMalloc || !residentHeapUsed) return;
  // glibc gives a thread's arena heaps of HEAP_MAX_SIZE, twice the largest
  // mmap threshold (2 x 32 MB on 64 bits), each aligned to its size: the one
  // holding a block starts at the block's address rounded down to 64 MB.
  // With M_TOP_PAD at 64 MB (useResidentHeap) a new heap is made readable and
  // writable whole, so the advice covers all of it.
  constexpr std::uintptr_t kArenaHeap = std::uintptr_t{64} << 20;
  void* volatile probe = std::malloc(1);
  const auto address = reinterpret_cast<std::uintptr_t>(probe);
  std::free(probe);
  const auto top = reinterpret_cast<std::uintptr_t>(sbrk(0));
  const auto mainHeap = reinterpret_cast<std::uintptr_t>(&end);
  if (address == 0 || (address >= mainHeap && address < top)) return;  // the main heap's own
  const std::uintptr_t heap = address & ~(kArenaHeap - 1);
  // Once per heap: a thread that takes over the arena of one that ended finds
  // it done. Never freed: detached helper threads may call this while the
  // process exits.
  static std::mutex* const mutex = new std::mutex;
  static std::vector<std::uintptr_t>* const advised = new std::vector<std::uintptr_t>;
  try {
    const std::lock_guard<std::mutex> lock(*mutex);
    if (std::find(advised->begin(), advised->end(), heap) != advised->end()) return;
    advised->push_back(heap);
  } catch (...) {
    return;  // no memory or no lock: the arena keeps 4 kB pages
  }
  madvise(reinterpret_cast<void*>(heap), kArenaHeap, MADV_HUGEPAGE);
  // NB: the heap's first 2 MB already hold glibc's own records in 4 kB
  // pages, and a 2 MB range with a page in it goes on faulting 4 kB at a
  // time: 490 faults of the caudate's helper thread, against none elsewhere
  // in its arena. A block over the rest of that range, kept and never
  // touched, leaves the thread's blocks to the huge pages after it. (It uses
  // no memory unless the kernel's khugepaged later makes that range one huge
  // page. MADV_COLLAPSE, which does so at once, took 5-6.5 ms a thread here,
  // as long as the faults it spares.)
  constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20, kSlack = 4096;
  const std::uintptr_t used = address - heap;
  if (used + kSlack < kHugePage) {
    void* volatile firstRange = std::malloc(kHugePage - used - kSlack);
    (void)firstRange;  // kept for good
  }
}

}  // namespace dynsub
