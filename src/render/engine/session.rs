//! The handle a driver (the studio, the CLI) holds: start or restart a job
//! with a new scene snapshot, cancel, and read the events of the worker
//! thread from a channel. Nothing here ever blocks the caller.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

use crossbeam_channel::{Receiver, Sender};

use super::events::{Notify, PassStats, RenderEvent};
use super::job::{run_job, JobContext, RenderJob};
use crate::render::image::LinearImage;

enum Command {
    Start(u64, RenderJob),
    Shutdown,
}

/// Handle to a background render worker: start (or restart) with a new scene
/// snapshot, cancel, and read events. Never blocks the caller.
pub struct RenderSession {
    commands: Sender<Command>,
    events: Receiver<RenderEvent>,
    generation: Arc<AtomicU64>,
    worker: Option<JoinHandle<()>>,
}

impl RenderSession {
    /// Start the session's worker thread (the OS may refuse one).
    pub fn new(notify: Option<Notify>) -> std::io::Result<Self> {
        let (commands, command_rx) = crossbeam_channel::unbounded();
        let (event_tx, events) = crossbeam_channel::unbounded();
        let generation = Arc::new(AtomicU64::new(0));
        let worker_generation = generation.clone();
        let worker = std::thread::Builder::new()
            .name("render-worker".into())
            .spawn(move || worker_loop(command_rx, event_tx, worker_generation, notify))?;
        Ok(Self { commands, events, generation, worker: Some(worker) })
    }

    /// Start rendering `job`, abandoning whatever was in flight. Returns the
    /// new generation; events of older ones may still arrive and should be dropped.
    pub fn start(&self, job: RenderJob) -> u64 {
        let generation = self.generation.fetch_add(1, Ordering::SeqCst) + 1;
        let _ = self.commands.send(Command::Start(generation, job));
        generation
    }

    /// Stop the current job; the worker goes idle.
    pub fn cancel(&self) {
        self.generation.fetch_add(1, Ordering::SeqCst);
    }

    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::SeqCst)
    }

    pub fn events(&self) -> &Receiver<RenderEvent> {
        &self.events
    }
}

impl Drop for RenderSession {
    fn drop(&mut self) {
        self.cancel();
        let _ = self.commands.send(Command::Shutdown);
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}

fn worker_loop(
    commands: Receiver<Command>,
    events: Sender<RenderEvent>,
    generation: Arc<AtomicU64>,
    notify: Option<Notify>,
) {
    let mut pools: Option<(usize, rayon::ThreadPool)> = None;
    while let Ok(mut command) = commands.recv() {
        // Only the newest queued job matters
        while let Ok(newer) = commands.try_recv() {
            command = newer;
        }
        let Command::Start(job_generation, job) = command else {
            return;
        };
        if generation.load(Ordering::SeqCst) != job_generation {
            continue;
        }
        let threads = job.settings.threads;
        if pools.as_ref().is_none_or(|(n, _)| *n != threads) {
            match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
                Ok(pool) => pools = Some((threads, pool)),
                Err(e) => {
                    let message = format!("could not start {threads} render threads: {e}");
                    let _ = events.send(RenderEvent::Failed { generation: job_generation, message });
                    continue;
                }
            }
        }
        if let Some((_, pool)) = &pools {
            let context = JobContext {
                generation: job_generation,
                stream_tiles: job.stream_tiles,
                current: &generation,
                events: &events,
                notify: notify.as_ref(),
            };
            pool.install(|| run_job(&context, &job));
        }
    }
}

/// Render a job to completion on its own session, for tests and tools that
/// want just the image (and the final statistics).
pub fn render_blocking(job: &RenderJob) -> Result<(LinearImage, PassStats), String> {
    let session = RenderSession::new(None).map_err(|e| format!("could not start the render worker: {e}"))?;
    let generation = session.start(RenderJob { stream_tiles: false, ..job.clone() });
    for event in session.events().iter() {
        match event {
            RenderEvent::Finished { generation: g, image, stats } if g == generation => {
                return Ok((Arc::try_unwrap(image).unwrap_or_else(|shared| (*shared).clone()), stats));
            }
            RenderEvent::Failed { generation: g, message } if g == generation => return Err(message),
            _ => {}
        }
    }
    Err("the render worker stopped".into())
}
