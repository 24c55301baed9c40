#pragma once
// A tool on a large input runs with glibc's transparent huge pages.
//
// Every first touch of a 4 kB page is a fault, and in a VM a fault and a TLB miss go through the
// hypervisor: on a freshly booted 2-core VM (Firecracker, PVM) a fault cost 11-18 us, and the bench
// mesh run (docs/benchmarks.md, "End to end") took 1.06-1.26 s with 42,900 faults, against
// 0.59-0.84 s and 2,100-2,400 faults with GLIBC_TUNABLES=glibc.malloc.hugetlb=1, which advises
// every block malloc takes from the kernel for 2 MB pages. glibc reads its tunables only when a
// process starts, so the tool starts itself again once with the tunable set.

namespace pcl_ddg {
namespace tools {

/**
 * Re-executes this process (/proc/self/exe, the same arguments) with glibc.malloc.hugetlb=1 added
 * to GLIBC_TUNABLES when the regular files among its arguments, and those directly inside the
 * folders among them, hold at least 32 MiB. Returns without doing so (and the tool runs as it
 * is) when they hold less (a start costs more than huge pages save on a small file), when
 * GLIBC_TUNABLES already names glibc.malloc.hugetlb (the user's choice, and the started process
 * itself), when PCL_DDG_HUGE_PAGES=0, under valgrind (whose tool would not follow the exec), or
 * when the exec fails.
 */
void restartOnHugePagesForLargeInputs();

}  // namespace tools
}  // namespace pcl_ddg
