#pragma once
// How much memory a piece of work may take, for refusing what cannot fit
// before the work starts rather than failing at its end.
#include <cstdint>
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

}  // namespace dynsub
