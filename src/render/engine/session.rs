//! The handle a driver (the studio, the CLI) holds: start or restart a job
//! with a new scene snapshot, cancel, and read the events of the worker
//! thread from a channel. Nothing here ever blocks the caller.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

use crossbeam_channel::{Receiver, Sender};

use super::events::{Notify, PassStats, RenderEvent};
use super::job::{run_job, JobContext, RenderJob};
use super::workers::Workers;
use crate::render::image::LinearImage;

enum Command {
    Start(u64, RenderJob),
    Shutdown,
}

/// Handle to a background render job: start (or restart) with a new scene
/// snapshot, cancel, and read events. Never blocks the caller. Its passes
/// run on `Workers` it may share with other sessions.
pub struct RenderSession {
    commands: Sender<Command>,
    events: Receiver<RenderEvent>,
    /// The worker's own sender, to report a worker that is gone.
    failures: Sender<RenderEvent>,
    generation: Arc<AtomicU64>,
    worker: Option<JoinHandle<()>>,
}

impl RenderSession {
    /// Start the session's thread (the OS may refuse one), which runs its
    /// jobs on `workers`.
    pub fn new(workers: &Workers, notify: Option<Notify>) -> std::io::Result<Self> {
        let (commands, command_rx) = crossbeam_channel::unbounded();
        let (event_tx, events) = crossbeam_channel::unbounded();
        let generation = Arc::new(AtomicU64::new(0));
        let worker_generation = generation.clone();
        let (workers, failures) = (workers.clone(), event_tx.clone());
        let worker = std::thread::Builder::new()
            .name("render-session".into())
            .spawn(move || worker_loop(&workers, command_rx, event_tx, worker_generation, notify))?;
        Ok(Self { commands, events, failures, generation, worker: Some(worker) })
    }

    /// Start rendering `job`, abandoning whatever was in flight. Returns the
    /// new generation; events of older ones may still arrive and should be
    /// dropped. Should the session's thread be gone (a bug that panicked
    /// it), the job fails at once with that said.
    pub fn start(&self, job: RenderJob) -> u64 {
        let generation = self.generation.fetch_add(1, Ordering::SeqCst) + 1;
        if self.commands.send(Command::Start(generation, job)).is_err() {
            let message = "the render thread has stopped; restart the program".to_string();
            // The receiver is ours: this cannot fail
            let _ = self.failures.send(RenderEvent::Failed { generation, message });
        }
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
    workers: &Workers,
    commands: Receiver<Command>,
    events: Sender<RenderEvent>,
    generation: Arc<AtomicU64>,
    notify: Option<Notify>,
) {
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
        let context = JobContext {
            generation: job_generation,
            stream_tiles: job.stream_tiles,
            stream_variance: job.stream_variance,
            estimate_noise: job.estimate_noise,
            strategies: job.strategies.clone(),
            current: &generation,
            events: &events,
            notify: notify.as_ref(),
        };
        // A bug that panics fails its job, and the session goes on: waiting
        // for the job's end would otherwise never end (the session holds a
        // sender of its own)
        let outcome = std::panic::catch_unwind(AssertUnwindSafe(|| run_job(workers, &context, &job)));
        if let Err(payload) = outcome {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            let message = format!("the render stopped on a bug (please report it): {what}");
            context.send(RenderEvent::Failed { generation: job_generation, message });
        }
    }
}

/// Render a job to completion on its own session and the process's shared
/// workers, for tests and tools that want just the image (and the final
/// statistics).
pub fn render_blocking(job: &RenderJob) -> Result<(LinearImage, PassStats), String> {
    let workers = Workers::shared().ok_or("could not start the render threads")?;
    render_blocking_on(workers, job)
}

/// `render_blocking` on `workers`.
pub fn render_blocking_on(workers: &Workers, job: &RenderJob) -> Result<(LinearImage, PassStats), String> {
    let session = RenderSession::new(workers, None).map_err(|e| format!("could not start the render worker: {e}"))?;
    let generation = session.start(RenderJob { stream_tiles: false, ..job.clone() });
    for event in session.events().iter() {
        match event {
            RenderEvent::Finished { generation: g, image, stats, .. } if g == generation => {
                return Ok((Arc::try_unwrap(image).unwrap_or_else(|shared| (*shared).clone()), stats));
            }
            RenderEvent::Failed { generation: g, message } if g == generation => return Err(message),
            _ => {}
        }
    }
    Err("the render worker stopped".into())
}
