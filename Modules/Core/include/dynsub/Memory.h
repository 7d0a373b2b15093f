#pragma once
// How much memory a piece of work may take, for refusing what cannot fit
// before the work starts rather than failing at its end.
#include <cstdint>
#include <functional>
#include <string>

namespace dynsub {

struct MemoryLimit {
  std::uint64_t bytes = 0;  // 0: unknown
  std::string what;         // "this machine's memory" or the address-space limit's name
};

// The lower of the machine's physical memory and this process's address-space
// limit (ulimit -v).
MemoryLimit usableMemory();

// `bytes` in GiB for a message, to one decimal: "1.5 GiB".
std::string gibibytes(long double bytes);

// Refuses, before any work, a size of work (samples per face, levels) whose
// memory would not fit in usableMemory(): `estimate(size)` is the bytes the
// work holds at that size, growing with it, to which a tenth and 160 MiB
// (threads' stacks, the allocator's arenas) are added for what it leaves
// out. Throws UsageError(path, "WHAT need about X GiB, more than ...: use at
// most OPTION N"), N the largest size from `smallest` that fits, or saying
// that even `smallest` does not.
void requireMemoryForSize(int size, int smallest, const std::function<long double(int)>& estimate,
                          const std::string& path, const std::string& what, const std::string& option);

}  // namespace dynsub
