#include "dynsub/Memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>

#include "dynsub/Error.h"

namespace dynsub {

MemoryLimit usableMemory() {
  MemoryLimit limit;
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && pageSize > 0) {
    limit.bytes = static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(pageSize);
    limit.what = "this machine's memory";
  }
  rlimit space{};
  if (getrlimit(RLIMIT_AS, &space) != 0 || space.rlim_cur == RLIM_INFINITY) return limit;
  // Under ulimit -v, what the process has mapped already (its libraries,
  // thread stacks) counts against the limit.
  unsigned long mappedPages = 0;
  if (std::FILE* statm = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(statm, "%lu", &mappedPages) != 1) mappedPages = 0;
    std::fclose(statm);
  }
  const std::uint64_t mapped = mappedPages * static_cast<std::uint64_t>(pageSize > 0 ? pageSize : 4096);
  const std::uint64_t left = space.rlim_cur > mapped ? space.rlim_cur - mapped : 1;
  if (limit.bytes == 0 || left < limit.bytes) {
    limit.bytes = left;
    limit.what = "the address space left under ulimit -v";
  }
  return limit;
}

std::string gibibytes(long double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1Lf GiB", bytes / (1u << 30));
  return text;
}

void requireMemoryForSize(int size, int smallest, const std::function<long double(int)>& estimate,
                          const std::string& path, const std::string& what, const std::string& option) {
  const MemoryLimit memory = usableMemory();
  const auto needed = [&](int n) { return 1.1L * estimate(n) + 160.0L * (1 << 20); };
  if (memory.bytes == 0 || needed(size) <= memory.bytes) return;
  int largest = size;
  while (largest > smallest && needed(largest) > memory.bytes) --largest;
  const std::string advice = needed(largest) <= memory.bytes ? "use at most " + option + " " + std::to_string(largest)
                                                             : "even " + option + " " + std::to_string(smallest) +
                                                                   " needs about " + gibibytes(needed(smallest));
  throw UsageError(path, what + " need about " + gibibytes(needed(size)) + ", more than " + memory.what + " (" +
                             gibibytes(memory.bytes) + "): " + advice);
}

}  // namespace dynsub
