//! The render threads: one pool that every session of a driver shares (the
//! studio's panes and its background reference alike), so four panes on two
//! cores run two workers, not eight. Its threads run below the priority of
//! the thread that made it, so the UI stays responsive while they render.

use std::sync::{Arc, OnceLock};

/// A shared pool of render threads. Cloning shares it.
#[derive(Clone)]
pub struct Workers {
    pool: Arc<rayon::ThreadPool>,
}

impl std::fmt::Debug for Workers {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Workers({})", self.threads())
    }
}

/// How far below normal the workers run (Unix niceness: 10 of 19).
const NICENESS: i32 = 10;

impl Workers {
    /// `threads` render threads (0: one per core), at low priority. The
    /// caller bounds `threads` (`limits::THREADS`): the OS may still refuse.
    pub fn new(threads: usize) -> std::io::Result<Self> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("render-{i}"))
            .start_handler(|_| lower_priority())
            .build()
            .map_err(std::io::Error::other)?;
        Ok(Self { pool: Arc::new(pool) })
    }

    /// One pool of every core for the whole process: what `render_blocking`
    /// and tests use. None if the OS refused its threads.
    pub fn shared() -> Option<&'static Workers> {
        static SHARED: OnceLock<Option<Workers>> = OnceLock::new();
        SHARED.get_or_init(|| Workers::new(0).ok()).as_ref()
    }

    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// Run `work` on the pool (the caller waits; its parallel loops spread
    /// over the pool's threads, shared with every other caller's).
    pub fn run<R: Send>(&self, work: impl FnOnce() -> R + Send) -> R {
        self.pool.install(work)
    }
}

/// Lower the calling thread's priority by `NICENESS` (on Linux, niceness is
/// per thread, and a new thread starts with its creator's).
#[allow(unsafe_code)]
fn lower_priority() {
    #[cfg(target_os = "linux")]
    // SAFETY: get/setpriority take plain integers; `who` = 0 is this thread.
    // A refusal (a sandbox) leaves the priority as it was, which is harmless.
    unsafe {
        let current = libc::getpriority(libc::PRIO_PROCESS, 0);
        libc::setpriority(libc::PRIO_PROCESS, 0, (current + NICENESS).min(19));
    }
    #[cfg(not(target_os = "linux"))]
    let _ = NICENESS;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workers_run_below_the_caller() {
        let workers = Workers::new(2).unwrap();
        assert_eq!(workers.threads(), 2);
        #[cfg(target_os = "linux")]
        {
            #[allow(unsafe_code)]
            // SAFETY: getpriority reads this thread's niceness.
            let nice = || unsafe { libc::getpriority(libc::PRIO_PROCESS, 0) };
            let caller = nice();
            let worker = workers.run(nice);
            assert_eq!(worker, (caller + NICENESS).min(19), "caller {caller}, worker {worker}");
        }
    }
}
