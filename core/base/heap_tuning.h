// Process-wide allocator setting for programs that run the pipeline frame after frame.
#pragma once

namespace tod {

// Keeps large freed blocks in the heap instead of returning them to the kernel. One 2048 x 1024
// frame builds about 150 MB of short-lived per-region tables (integral images, run indexes,
// bounds); glibc serves such blocks with fresh mappings and unmaps them on free, so each frame
// would fault in and zero them again (about 3 % of a frame in page faults alone). With this the
// heap keeps them, and the resident size stays at the peak of one frame per worker. Returns
// false if the C library refused the setting (harmless: only slower). Call once, early in main().
bool RetainLargeAllocations();

}  // namespace tod
