//! The memory a pass frees stays for the next (`keep_freed_memory`). A
//! file of its own: its test runs alone in its process, so no other
//! thread allocates from the heap it watches.

#![cfg(all(target_os = "linux", target_env = "gnu"))]

use gi_studio::render::engine::keep_freed_memory;

/// Minor page faults this thread has taken.
#[allow(unsafe_code)]
fn faults() -> i64 {
    // SAFETY: getrusage fills the zeroed struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_THREAD, &mut usage) };
    usage.ru_minflt
}

/// A pass's worth of buffer, freed and allocated again: the second round
/// finds its pages already there (without the thresholds, each round
/// faulted in all 4096 of them).
#[test]
fn a_buffer_freed_is_not_faulted_in_again() {
    keep_freed_memory();
    // A thread of its own: its own heap, and faults counted for it alone
    std::thread::spawn(|| {
        let pages = 4096;
        let round = || {
            let before = faults();
            let buffer = std::hint::black_box(vec![1u8; pages * 4096]);
            drop(buffer);
            faults() - before
        };
        let first = round();
        let second = round();
        assert!(first > pages as i64 / 2, "the first round faults its pages in ({first})");
        assert!(second < pages as i64 / 20, "{second} faults in the second round, {first} in the first");
    })
    .join()
    .expect("the thread finishes");
}
