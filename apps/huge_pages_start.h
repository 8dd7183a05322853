// Our programs that own their process (the command line, whose `edit` is the editor's server,
// and the editor's benchmark, which measures that server's work) have glibc's malloc ask the
// kernel for transparent huge pages on its large blocks: the tunable glibc.malloc.hugetlb=1,
// read only when a program starts, so the program starts itself once more with it. Under a
// hypervisor the first touch of a 4 KB page costs about 8.5 us, and every stage's fresh arrays,
// CHOLMOD's factor included, paid it: the 692k armadillo's deform took 16.7 s without them and
// 9.5 s with them, the 2.77M one 100 s and 47 s, at the same peak memory (docs/results.md, "Huge
// pages for the whole program"). A GLIBC_TUNABLES that names the tunable (=0 to turn it off) is
// kept as it is; a glibc without the tunable ignores it, and a failed restart carries on as it
// is. The library itself leaves a host's process (Python, Blender) as it finds it.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>

namespace specdeform::apps {

inline void restart_with_huge_pages(char** argv) {
#if defined(__GLIBC__) && defined(__linux__)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr && std::strstr(tunables, "glibc.malloc.hugetlb") != nullptr) return;
  const std::string value = (tunables != nullptr && *tunables != '\0')
                                ? std::string(tunables) + ":glibc.malloc.hugetlb=1"
                                : std::string("glibc.malloc.hugetlb=1");
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
#else
  (void)argv;
#endif
}

}  // namespace specdeform::apps
