#include "malloc_tunables.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace hm {

std::string malloc_tunables_with(const char* current, const std::string& wanted) {
  const std::string tunables = current ? current : "";
  if (tunables.find("glibc.malloc.hugetlb") != std::string::npos) return "";
  return tunables + (tunables.empty() ? "" : ":") + wanted;
}

void rerun_with_malloc_tunables(char** argv, const std::string& wanted) {
#if defined(__GLIBC__) && defined(__linux__)
  const std::string tunables = malloc_tunables_with(std::getenv("GLIBC_TUNABLES"), wanted);
  if (tunables.empty()) return;
  std::error_code ec;
  const std::string self = std::filesystem::read_symlink("/proc/self/exe", ec).string();
  if (ec || self.empty()) return;
  if (::setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
  ::execv(self.c_str(), argv);  // returns only on failure: go on as we are
#else
  (void)argv;
  (void)wanted;
#endif
}

}  // namespace hm
