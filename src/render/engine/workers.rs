//! The render threads: one pool that every session of a driver shares (the
//! studio's panes and its background reference alike), so four panes on two
//! cores run two workers, not eight. Its threads run below the priority of
//! the thread that made it, so the UI stays responsive while they render.
//!
//! The sessions' stages (a pass, a photon map's build) take the pool one at
//! a time, never two at once: a thread that waits inside one stage's
//! parallel loop would otherwise pick up another session's stage and run it
//! to the end before it came back, and the first stage's time would hold
//! the second's. Taking turns, a stage's time is its own work on every
//! thread of the pool, which is what a pane's clock counts however many
//! panes render beside it. Whose turn is next is fair by time, not by
//! stage: the session that has had the least of the pool goes first, so a
//! pane of 20-ms passes beside one of 300-ms passes gets as many seconds,
//! not as few passes.

use std::sync::{Arc, Condvar, Mutex, OnceLock, PoisonError};
use std::time::{Duration, Instant};

/// A shared pool of render threads. Cloning shares it.
#[derive(Clone)]
pub struct Workers {
    pool: Arc<rayon::ThreadPool>,
    turns: Arc<Turns>,
}

impl std::fmt::Debug for Workers {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Workers({})", self.threads())
    }
}

/// One caller's account of the pool's time (a render job keeps one for all
/// its stages): what decides whose turn is next.
#[derive(Clone, Copy, Debug, Default)]
pub struct Share {
    /// The pool's time this caller has had, over its weight, counted from
    /// where the least served caller stood when it came (`Queue::arrive`).
    had: Duration,
    /// How many callers' worth of the pool it takes (0 counts as 1): the
    /// studio's reference, while it is young, as much as all its panes.
    pub weight: u32,
}

impl Share {
    /// The caller had the pool for `took`: it counts as `took` over its weight.
    fn spent(&mut self, took: Duration) {
        self.had += took / self.weight.max(1);
    }
}

/// The callers waiting for the pool, and whether one has it.
#[derive(Debug, Default)]
struct Queue {
    /// (time had, ticket) of each waiting caller
    waiting: Vec<(Duration, u64)>,
    next_ticket: u64,
    running: bool,
    /// The time had of the last caller to start: one that comes new (or
    /// comes back after a rest) stands here, not at zero, so it does not
    /// take the pool from the others until it has caught up.
    floor: Duration,
}

impl Queue {
    /// A caller with `share` asks for the pool: its ticket.
    fn arrive(&mut self, share: &mut Share) -> u64 {
        share.had = share.had.max(self.floor);
        let ticket = self.next_ticket;
        self.next_ticket += 1;
        self.waiting.push((share.had, ticket));
        ticket
    }

    /// Whether `ticket` takes the pool now (and if so, it has it): the pool
    /// is free and no waiting caller has had less (the earlier ticket on a tie).
    fn start(&mut self, ticket: u64) -> bool {
        let first = self.waiting.iter().enumerate().min_by_key(|(_, entry)| **entry);
        match first {
            Some((at, &(had, first))) if !self.running && first == ticket => {
                self.waiting.swap_remove(at);
                self.running = true;
                self.floor = self.floor.max(had);
                true
            }
            _ => false,
        }
    }

    fn finish(&mut self) {
        self.running = false;
    }
}

#[derive(Debug, Default)]
struct Turns {
    queue: Mutex<Queue>,
    changed: Condvar,
}

impl Turns {
    /// Waits for the caller's turn; the turn passes on when the guard drops
    /// (a stage that panics passes it on too).
    fn take(&self, share: &mut Share) -> Turn<'_> {
        // Nothing runs under the lock but the queue's bookkeeping, so a
        // poisoned lock still holds a consistent queue
        let mut queue = self.queue.lock().unwrap_or_else(PoisonError::into_inner);
        let ticket = queue.arrive(share);
        while !queue.start(ticket) {
            queue = self.changed.wait(queue).unwrap_or_else(PoisonError::into_inner);
        }
        Turn(self)
    }
}

struct Turn<'a>(&'a Turns);

impl Drop for Turn<'_> {
    fn drop(&mut self) {
        self.0.queue.lock().unwrap_or_else(PoisonError::into_inner).finish();
        self.0.changed.notify_all();
    }
}

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
        Ok(Self { pool: Arc::new(pool), turns: Arc::default() })
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

    /// Run `work` on the pool in its turn, as a caller that comes once (the
    /// caller waits; its parallel loops spread over all the pool's threads).
    pub fn run<R: Send>(&self, work: impl FnOnce() -> R + Send) -> R {
        self.run_in_turn(&mut Share::default(), work).0
    }

    /// `run` for a caller that comes again with its `share` (which this
    /// adds to), and how long `work` took once its turn came: its own time,
    /// not the time it waited for other stages.
    pub fn run_in_turn<R: Send>(&self, share: &mut Share, work: impl FnOnce() -> R + Send) -> (R, Duration) {
        // Asked from inside one of the pool's stages: that stage's turn
        if self.pool.current_thread_index().is_some() {
            let start = Instant::now();
            return (self.pool.install(work), start.elapsed());
        }
        let turn = self.turns.take(share);
        let start = Instant::now();
        let result = self.pool.install(work);
        let took = start.elapsed();
        drop(turn);
        share.spent(took);
        (result, took)
    }
}

/// How far below normal the workers run (Unix niceness: 10 of 19).
const NICENESS: i32 = 10;

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

    fn share(seconds: u64) -> Share {
        Share { had: Duration::from_secs(seconds), weight: 1 }
    }

    /// A caller of weight 3 beside one of weight 1, both with stages of a
    /// second: three turns to one.
    #[test]
    fn a_weighted_caller_has_the_pool_as_often_as_its_weight_says() {
        let mut queue = Queue::default();
        let (mut heavy, mut light) = (Share { weight: 3, ..share(0) }, share(0));
        let mut turns = [0; 2];
        for _ in 0..40 {
            let tickets = [queue.arrive(&mut heavy), queue.arrive(&mut light)];
            let first = tickets.iter().position(|&t| queue.start(t)).expect("one of them starts");
            queue.finish();
            turns[first] += 1;
            [&mut heavy, &mut light][first].spent(Duration::from_secs(1));
            // Both ask afresh next round
            queue.waiting.clear();
        }
        assert_eq!(turns, [30, 10], "turns of the heavy and the light caller");
    }

    #[test]
    fn the_caller_that_has_had_least_of_the_pool_goes_next() {
        let mut queue = Queue::default();
        let (mut long, mut short) = (share(0), share(0));
        let first = queue.arrive(&mut long);
        assert!(queue.start(first), "a free pool goes to the only caller");
        // The long stage ran 3 s; meanwhile the short one waits
        let waiting = queue.arrive(&mut short);
        assert!(!queue.start(waiting), "never two stages at once");
        queue.finish();
        long.had += Duration::from_secs(3);
        let again = queue.arrive(&mut long);
        assert!(!queue.start(again), "the long one has had more: it waits");
        assert!(queue.start(waiting));
        queue.finish();
        // The short one goes on until it has had as much
        short.had += Duration::from_secs(2);
        let more = queue.arrive(&mut short);
        assert!(queue.start(more));
        queue.finish();
        short.had += Duration::from_secs(2);
        let after = queue.arrive(&mut short);
        assert!(!queue.start(after), "4 s against 3 s: the long one's turn");
        assert!(queue.start(again));
    }

    #[test]
    fn a_newcomer_stands_where_the_least_served_stood_and_ties_go_in_order() {
        let mut queue = Queue::default();
        let mut old = share(10);
        let ticket = queue.arrive(&mut old);
        assert!(queue.start(ticket));
        queue.finish();
        // New callers do not start at zero, or they would hold the pool
        // for the 10 s the old one has had
        let (mut first, mut second) = (Share::default(), Share::default());
        let (a, b) = (queue.arrive(&mut second), queue.arrive(&mut first));
        assert_eq!((second.had, first.had), (Duration::from_secs(10), Duration::from_secs(10)));
        old.had += Duration::from_secs(1);
        let c = queue.arrive(&mut old);
        assert!(!queue.start(b) && !queue.start(c), "the earlier of the tie goes first");
        assert!(queue.start(a));
        queue.finish();
        assert!(!queue.start(c));
        assert!(queue.start(b));
    }

    /// Callers on several threads, each stage a parallel loop the pool's
    /// threads share: no stage starts while another runs, and each caller's
    /// time is its stages' alone, so the times add up to no more than the
    /// whole run.
    #[test]
    fn stages_of_different_callers_never_overlap() {
        use rayon::prelude::*;
        use std::sync::atomic::{AtomicUsize, Ordering};
        let workers = Workers::new(2).unwrap();
        let (inside, most) = (AtomicUsize::new(0), AtomicUsize::new(0));
        let start = Instant::now();
        let busy: Vec<Duration> = std::thread::scope(|scope| {
            let callers: Vec<_> = (0..3)
                .map(|caller| {
                    let (workers, inside, most) = (&workers, &inside, &most);
                    scope.spawn(move || {
                        let mut share = Share::default();
                        let mut busy = Duration::ZERO;
                        for _ in 0..20 {
                            let ((), took) = workers.run_in_turn(&mut share, || {
                                most.fetch_max(inside.fetch_add(1, Ordering::SeqCst) + 1, Ordering::SeqCst);
                                let work = |i: u64| (0..20_000 * (caller as u64 + 1)).fold(i, |a, b| a ^ (a << 1) ^ b);
                                std::hint::black_box((0..64u64).into_par_iter().map(work).reduce(|| 0, |a, b| a ^ b));
                                inside.fetch_sub(1, Ordering::SeqCst);
                            });
                            busy += took;
                        }
                        busy
                    })
                })
                .collect();
            callers.into_iter().map(|caller| caller.join().unwrap()).collect()
        });
        let whole = start.elapsed();
        assert_eq!(most.load(Ordering::SeqCst), 1, "two stages ran at once");
        let total: Duration = busy.iter().sum();
        assert!(total <= whole, "the callers' times {busy:?} add up to more than the run ({whole:?})");
    }
}
