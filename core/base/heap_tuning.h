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

// Serves every thread's allocations from one heap (glibc's main arena) instead of an arena per
// thread. With RetainLargeAllocations each arena keeps the peak of the frames its threads ran, so
// a server of W workers held W frame peaks side by side although they rarely coincide; one shared
// heap lets a worker reuse the pages another has freed. Measured with `tod_server --workers 2`
// after 550 real and synthetic requests (deploy/bench_server.sh): peak RSS 405 -> 315-330 MB, the
// same throughput. For the server, whose workers allocate a few large blocks per stage; not for
// the trainer's many small per-frame allocations. A MALLOC_ARENA_MAX in the environment wins:
// then nothing is changed and this returns false, as it does where the C library refuses.
// Call once, early in main(), before any thread starts.
bool ShareOneHeapArena();

// Hands the heap's free pages back to the kernel (glibc's malloc_trim), keeping the address
// space. For a loop that keeps a little of every frame (the trainer's sampled rows): with
// RetainLargeAllocations the frames' freed tables stay resident, and how well the next frame
// reuses them depends on where the kept blocks fell, which shifts with anything that moves the
// heap's layout (the dataset path's length did): the same 96-frame training peaked at 90 MB or
// at 127-203 MB. Released after each frame, the peak is one frame's working set plus what is
// kept, wherever the blocks fall. Costs the next frame's first touch of those pages.
void ReleaseFreeHeapPages();

// Whether ShareOneHeapArena succeeded in this process (what a benchmark reports beside its RSS).
bool HeapArenaShared();

}  // namespace tod
