#pragma once
// A tool on a large input runs with glibc's transparent huge pages.
//
// Every first touch of a 4 KiB page is a fault, and in a VM a fault goes through the hypervisor:
// on a freshly booted 2-core VM (Firecracker, PVM) one cost 11-18 us. With
// GLIBC_TUNABLES=glibc.malloc.hugetlb=1, malloc advises the memory it takes from the kernel for
// 2 MiB pages (glibc 2.35 and later, with the kernel's THP in "madvise" mode): there, the
// 10M-point LAS normals went from 15.6 to 12.1 s and 368,603 to 43,848 faults
// (docs/benchmarks.md, "LAS end to end"). glibc reads its tunables only when a process starts, so
// the tool starts itself again once, with the tunable set.

namespace pcl_ddg {
namespace tools {

/**
 * Re-executes this process (its executable, the same arguments) with glibc.malloc.hugetlb=1 added
 * to GLIBC_TUNABLES when the regular files among its arguments, and those directly inside the
 * folders among them, hold at least 32 MiB. Returns without doing so, and the tool runs as it is:
 * when they hold less (a second start costs more than huge pages save on a small file); when the
 * tunable would do nothing (glibc before 2.35, the kernel's THP not in "madvise" mode); when
 * GLIBC_TUNABLES already names glibc.malloc.hugetlb (the user's choice, and the restarted process
 * itself); where detail::hugePagesAllowed() says no (a sanitizer build, valgrind, whose tool would
 * not follow the exec, or PCL_DDG_HUGE_PAGES=0); or when the exec fails. With -memory (a budget
 * measured in 4 KiB pages) it sets PCL_DDG_HUGE_PAGES=0, so the library's large arrays
 * (pcl_ddg/large_array.h) stay on 4 KiB pages too; call it before any of them is made.
 */
void restartOnHugePagesForLargeInputs();

}  // namespace tools
}  // namespace pcl_ddg
