// glibc's malloc tunables for an executable's large arrays. A million-cell mesh is a few dozen
// arrays of tens of megabytes; on this kernel (transparent_hugepage/enabled = madvise) the kernel
// faults and clears them 4 KiB at a time unless malloc asks for huge pages, which glibc does only
// when GLIBC_TUNABLES says so when the process starts. They change the speed, never a result.
// Measurements: docs/performance.md (sessions 10 and 31).
#pragma once
#include <string>

namespace hm {

/// Transparent huge pages for the heap and the big blocks: meshgen and its benchmark.
inline constexpr const char* kMallocHugePages = "glibc.malloc.hugetlb=1";
/// The same, and big blocks from the heap (an array freed early is reused, not cleared again):
/// fvcheck, whose reader frees its temporaries before the checks allocate theirs.
inline constexpr const char* kMallocHugePagesHeapReuse = "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=4294967295";

/// What GLIBC_TUNABLES (`current`, null if unset) becomes with `wanted` appended; "" when
/// `current` already names glibc.malloc.hugetlb (the user's choice stands: e.g. =0 to keep
/// glibc's defaults, or to profile under valgrind).
std::string malloc_tunables_with(const char* current, const std::string& wanted);

/// Runs this executable again (execv of /proc/self/exe: same process id, same arguments) with
/// GLIBC_TUNABLES = malloc_tunables_with(its value, wanted). Returns only when there is nothing to
/// change or when the exec failed; the program then goes on as it is. Call it first in main.
void rerun_with_malloc_tunables(char** argv, const std::string& wanted);

}  // namespace hm
