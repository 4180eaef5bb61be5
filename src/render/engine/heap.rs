//! What the process asks of the C allocator. A pass allocates its large
//! buffers afresh (SPPM's photons, their grid's columns, light vertices)
//! and frees them at its end; glibc hands such memory back to the kernel
//! (an `mmap` per buffer above 128 KiB at first, and a thread's heap
//! trimmed once 128 KiB lie free at its top), so the next pass faults every
//! page in again, zeroed by the kernel, in system time every pass.

/// The largest `M_MMAP_THRESHOLD` glibc takes on 64-bit (half its 64 MiB
/// thread heaps): buffers up to this size come from the heaps.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const MMAP_THRESHOLD: i32 = 32 << 20;

/// Keep memory freed by one pass for the next: buffers up to 32 MiB from
/// the heaps, which are not trimmed. The process's footprint then stays at
/// its peak (SPPM's cornell: 93 MiB where it fell back to 61 between
/// passes). Elsewhere than glibc, nothing.
#[allow(unsafe_code)]
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt takes two integers and changes only glibc's
    // thresholds; a refusal returns 0 and leaves them as they were.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD);
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
    }
}
