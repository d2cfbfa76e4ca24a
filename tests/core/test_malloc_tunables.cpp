// What the executables put into GLIBC_TUNABLES before running themselves again
// (meshgen/core/malloc_tunables.hpp).
#include <gtest/gtest.h>

#include "meshgen/core/malloc_tunables.hpp"

using hm::malloc_tunables_with;

TEST(MallocTunables, AppendsToWhatTheUserSet) {
  EXPECT_EQ(malloc_tunables_with(nullptr, hm::kMallocHugePages), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(malloc_tunables_with("", hm::kMallocHugePages), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(malloc_tunables_with("glibc.malloc.arena_max=2", hm::kMallocHugePagesHeapReuse),
            "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=4294967295");
}

TEST(MallocTunables, TheUsersHugePageChoiceStands) {
  // Already set (by the user, or by the first run of the program itself): no second run.
  EXPECT_EQ(malloc_tunables_with("glibc.malloc.hugetlb=0", hm::kMallocHugePages), "");
  EXPECT_EQ(malloc_tunables_with("glibc.malloc.hugetlb=1", hm::kMallocHugePages), "");
  EXPECT_EQ(malloc_tunables_with("glibc.malloc.check=3:glibc.malloc.hugetlb=1", hm::kMallocHugePagesHeapReuse), "");
}
