#pragma once
// Freed memory stays with the process, in 2 MB pages, instead of going back to
// the system. On the virtual machines DynSub is measured on, each first touch
// of a 4 kB page costs about 30 us of kernel time, and glibc's defaults give
// every large block (a k-d tree, a factor, a tessellation) back at free() and
// fault it in again at the next malloc(): the kitten's fit took 119 000 page
// faults, 3.5 s of its 11 s (Documentation/Performance.md).

namespace dynsub {

// Call once, first thing in main(), before any thread exists: keeps blocks up
// to 32 MB in the heap, never trims it below 1 GB, grows it 64 MB at a time
// and asks for transparent huge pages on what it has grown (the kernel's
// "madvise" mode, this machine's; "always" needs no asking, "never" refuses).
// That is the main heap; threads' arenas keep glibc's 4 kB pages
// (ResidentHeap.cpp says why). Address space is reserved, memory is only used
// where touched. Other allocators (a sanitizer's) are left alone.
void useResidentHeap();

// Call first thing on a thread DynSub starts, in a program that called
// useResidentHeap(): the thread's own arena (a 64 MB region glibc maps for
// it, kept, since the heap is never trimmed) gets transparent huge pages too.
// Nothing when the thread allocates from the main heap, when no arena is
// glibc's (a sanitizer's allocator), or when useResidentHeap() was not called.
// NB: threads did most of a run's page faults: 60 % of the caudate
// segmentation's 5 100 (its outputs written alongside, the next level's
// operators built ahead) and 87 % of the kitten's fit's 14 000, at 12-15 us
// each here against under 4 us a 4 kB share of a huge page
// (Documentation/Performance.md, twenty-fourth session).
void useResidentArena();

}  // namespace dynsub
