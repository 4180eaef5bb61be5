//! winit 0.30's X11 backend unwraps the X server's answers about its own
//! window, so when the server destroys the window under it (`xdotool
//! windowclose`, another client killing it) it panics on the UI thread; no
//! newer winit or eframe changes that. The panic unwinds through eframe's
//! loop and drops the studio, which writes its state as it goes (`Drop for
//! StudioApp`); this turns that panic into a clean end and lets any other
//! panic through as it was.

use std::panic::{self, AssertUnwindSafe, PanicHookInfo};
use std::sync::{Arc, Mutex};

/// The window system took the window away: what it said.
#[derive(Debug)]
pub struct WindowLost(pub String);

/// Run `window` (the event loop); a panic from the window system's X11 code
/// on this thread comes back as `WindowLost`, any other panic goes on.
pub fn catching_window_loss<T>(window: impl FnOnce() -> T) -> Result<T, WindowLost> {
    let previous: Arc<dyn Fn(&PanicHookInfo<'_>) + Send + Sync> = Arc::from(panic::take_hook());
    let lost = Arc::new(Mutex::new(None));
    let ui_thread = std::thread::current().id();
    {
        let (previous, lost) = (previous.clone(), lost.clone());
        panic::set_hook(Box::new(move |info| {
            let here = std::thread::current().id() == ui_thread;
            match info.location().filter(|_| here).filter(|at| is_window_system(at.file())) {
                Some(_) => {
                    if let Ok(mut slot) = lost.lock() {
                        *slot = Some(panic_message(info));
                    }
                }
                None => previous(info),
            }
        }));
    }
    let outcome = panic::catch_unwind(AssertUnwindSafe(window));
    panic::set_hook(Box::new(move |info| previous(info)));
    match outcome {
        Ok(value) => Ok(value),
        Err(payload) => match lost.lock().ok().and_then(|mut slot| slot.take()) {
            Some(message) => Err(WindowLost(message)),
            None => panic::resume_unwind(payload),
        },
    }
}

/// Whether a panic at `file` is winit's X11 code.
fn is_window_system(file: &str) -> bool {
    let file = file.replace('\\', "/");
    file.contains("/winit-") && file.contains("/x11/")
}

fn panic_message(info: &PanicHookInfo<'_>) -> String {
    let payload = info.payload();
    let text = payload.downcast_ref::<&str>().copied().or_else(|| payload.downcast_ref::<String>().map(String::as_str));
    text.unwrap_or("a panic without a message").to_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_winits_x11_code_is_the_window_system() {
        let registry = "/root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f";
        assert!(is_window_system(&format!("{registry}/winit-0.30.13/src/platform_impl/linux/x11/window.rs")));
        assert!(!is_window_system(&format!("{registry}/winit-0.30.13/src/platform_impl/linux/wayland/mod.rs")));
        assert!(!is_window_system("src/app/x11/studio.rs"));
    }

    #[test]
    fn other_panics_go_on_and_values_come_back() {
        assert_eq!(catching_window_loss(|| 7).unwrap(), 7);
        let other = panic::catch_unwind(|| catching_window_loss(|| panic!("a bug of ours")));
        let payload = other.expect_err("a panic that is not the window system's goes on");
        assert_eq!(payload.downcast_ref::<&str>(), Some(&"a bug of ours"));
    }
}
