// Transparent huge pages for the mesher's heap (docs/svrc-design.md §8 item 49).
//
// A refinement grows a few hundred MB to GB of arrays and touches every page
// once: with 4 KiB pages that is one page fault per 4 KiB, and on the 2-core
// VMs we measure on a fault costs ~10 µs (cube --max-volume 1e-6: 360,009
// minor faults, 3.1 s of system time in a 19.7 s run). glibc (2.35 and later)
// backs malloc's heap with 2 MiB pages when the tunable glibc.malloc.hugetlb=1
// is set, which the kernel honours when transparent huge pages are in
// "madvise" mode (Debian's default): 16,378 faults and 16.4 s wall on the same
// run, byte-identical output. Tunables are read only at process start, so
// the process re-executes itself once with the tunable set.
#pragma once

namespace svrc::util {

// Re-executes this program (/proc/self/exe, the same argv) with
// glibc.malloc.hugetlb=1 added to GLIBC_TUNABLES, and returns only when it
// did not: the tunable is already set (by the user or by an earlier
// re-execution), SVRC_HUGE_PAGES=0 is set, transparent huge pages are not in
// "madvise" mode (with "always" every large mapping already gets them, with
// "never" none can), or exec failed (the environment is restored). Call it
// first thing in main(), before threads exist.
void ReexecWithHugePageHeap(char** argv);

// Whether this process started with glibc.malloc.hugetlb=1 (by
// ReexecWithHugePageHeap or the user); `svrc mesh --stats` prints it.
bool HugePageHeapRequested();

// Fixes glibc's mmap threshold at kMmapThreshold (mallopt M_MMAP_THRESHOLD):
// blocks from that size on are mapped on their own and go back to the system
// when freed. glibc's default threshold is dynamic: freeing a mapped block
// raises it to that block's size (up to 32 MiB), and the refinement frees
// its 29-32 MB cache tables at every labelling (docs/svrc-design.md §8 items
// 56, 74), after which every array below that size came from the main heap,
// whose freed pieces stay resident. Measured (session 45, cube.poly
// --max-volume 1e-6, the same output bytes): peak RSS 373 -> 307 MB on the
// ordinary heap, 346-412 -> 305-314 MB on the huge-page heap, wall time
// within this box's noise; --max-volume 1e-5 47.5 -> 44-47 MB (a 4 MiB
// threshold: 51.5 MB; 256 KiB: 42-43 MB, with 40% more page faults on
// 1e-6); wedge-1.smesh 167-171 -> 156-157 MB. Nothing is
// done when GLIBC_TUNABLES already names glibc.malloc.mmap_threshold (the
// user's choice) or SVRC_MMAP_THRESHOLD=0. Call it first thing in main().
inline constexpr int kMmapThreshold = 1 << 20;
void FixMmapThreshold();

}  // namespace svrc::util
