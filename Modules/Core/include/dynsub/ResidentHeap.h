#pragma once
// Freed memory stays with the process, in 2 MB pages, instead of going back to
// the system. On the virtual machines DynSub is measured on, each first touch
// of a 4 kB page costs about 30 us of kernel time, and glibc's defaults give
// every large block (a k-d tree, a factor, a tessellation) back at free() and
// fault it in again at the next malloc(): the kitten's fit took 119 000 page
// faults, 3.5 s of its 11 s (Documentation/Performance.md).

namespace dynsub {

// Whether malloc is glibc's, whose heap and arenas these functions shape: not
// in a build with a sanitizer, whose allocator replaces it.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kGlibcMalloc = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
inline constexpr bool kGlibcMalloc = false;
#else
inline constexpr bool kGlibcMalloc = true;
#endif
#else
inline constexpr bool kGlibcMalloc = true;
#endif

// Call once, first thing in main(), before any thread exists: keeps blocks up
// to 32 MB in the heap, never trims it below 1 GB, grows it 64 MB at a time
// and asks for transparent huge pages on what it has grown (the kernel's
// "madvise" mode, this machine's; "always" needs no asking, "never" refuses).
// That is the main heap; threads keep arenas of their own (ResidentHeap.cpp
// says why), which useResidentArena gives huge pages. Address space is
// reserved, memory is only used where touched. Other allocators (a
// sanitizer's) are left alone.
void useResidentHeap();

// Call first thing on a thread DynSub starts, in a program that called
// useResidentHeap(): the first heap of the thread's own arena (a 64 MB region
// glibc maps for it, kept, since heaps are never trimmed; an arena that
// outgrows it gets more, which stay in 4 kB pages) gets transparent huge
// pages too. Nothing when the thread allocates from the main heap, in a
// sanitizer build, or when useResidentHeap() was not called. Assumes glibc's
// malloc (as useResidentHeap does): an allocator put in with LD_PRELOAD is
// not supported. Never throws.
// NB: threads did most of a run's page faults: 60 % of the caudate
// segmentation's 5 100 (its outputs written alongside, the next level's
// operators built ahead) and 87 % of the kitten's fit's 14 000, at 12-15 us
// each here against under 4 us a 4 kB share of a huge page
// (Documentation/Performance.md, twenty-fourth session).
void useResidentArena() noexcept;

}  // namespace dynsub
