//! The progressive engine: a job's passes over tiles in parallel, each
//! finished tile sent at once, stopped by a generation counter that every
//! tile checks, so a restart never waits for a pass to end. The studio and
//! the CLI both drive it through a `RenderSession`.

mod events;
mod heap;
mod job;
mod session;
mod workers;

pub use events::{Notify, PassStats, RenderEvent, TileUpdate};
pub use heap::keep_freed_memory;
pub use job::{RenderJob, Switch, Weight};
pub use session::{render_blocking, render_blocking_on, RenderSession};
pub use workers::Workers;
