//! Screenshots of the window and the comparison sheet (the panes' area with
//! their labels): asked of egui at a frame, saved when the image arrives.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use anyhow::{bail, Result};
use eframe::egui;

use crate::fileio::{self, SIGNATURE};
use crate::render::image::{save_png, ImageFormat};

/// A screenshot on its way: where, which part, and when.
pub struct ScreenshotRequest {
    pub path: PathBuf,
    pub crop: Option<egui::Rect>,
    /// Wait until every pane has this many passes (the --screenshot mode).
    pub after_passes: Option<u32>,
    /// Or until this moment (`--quit-after-seconds`).
    pub at: Option<std::time::Instant>,
    pub quit_after: bool,
    /// Frames to wait first, so the dialog that asked for it is gone.
    pub delay: u8,
    pub requested: bool,
    pub result: Arc<Mutex<Option<Result<(), String>>>>,
}

impl ScreenshotRequest {
    /// A screenshot the user asked for from a dialog, taken a few frames
    /// later (once the dialog is gone); refused unless it is a PNG.
    pub fn asked(path: PathBuf, crop: Option<egui::Rect>) -> Result<Self, String> {
        if !matches!(ImageFormat::of(&path), Ok(ImageFormat::Png)) {
            return Err(format!("{}: screenshots are PNG files (end the name in .png)", path.display()));
        }
        Ok(Self::new(path, crop))
    }

    pub fn new(path: PathBuf, crop: Option<egui::Rect>) -> Self {
        Self {
            path,
            crop,
            after_passes: None,
            at: None,
            quit_after: false,
            delay: 2,
            requested: false,
            result: Arc::new(Mutex::new(None)),
        }
    }
}

impl ScreenshotRequest {
    /// Advance one frame: wait out the delay, ask egui for the image once
    /// `ready`, and give the outcome once it is saved.
    pub fn step(&mut self, ctx: &egui::Context, ready: bool) -> Option<Result<PathBuf, String>> {
        if !self.requested {
            if self.delay > 0 {
                self.delay -= 1;
            } else if ready {
                self.requested = true;
                let (path, crop, result, repaint) = (self.path.clone(), self.crop, self.result.clone(), ctx.clone());
                let pixels_per_point = ctx.pixels_per_point();
                ctx.request_screenshot(move |image| {
                    let outcome = save_screenshot(&image, crop, pixels_per_point, &path);
                    if let Ok(mut slot) = result.lock() {
                        *slot = Some(outcome);
                    }
                    repaint.request_repaint();
                });
            }
            // Waiting for passes: the tiles ask for frames as they come
            ctx.request_repaint_after(super::status::RENDER_REPAINT);
            return None;
        }
        let outcome = self.result.lock().ok().and_then(|mut slot| slot.take());
        if outcome.is_none() {
            ctx.request_repaint();
        }
        outcome.map(|saved| saved.map(|()| self.path.clone()))
    }
}

/// The screenshot on its way, if any, and where a failed headless one
/// leaves its error for the binary to exit with.
#[derive(Default)]
pub struct Capture {
    request: Option<ScreenshotRequest>,
    exit_error: Arc<Mutex<Option<String>>>,
}

/// A screenshot done: where it went or why it failed, and whether to quit.
pub struct Captured {
    pub result: Result<PathBuf, String>,
    pub quit: bool,
}

impl Capture {
    /// `--screenshot PATH`: once every pane has `passes` passes (or, given
    /// `seconds`, once that long has passed), then quit.
    pub fn headless(path: PathBuf, passes: u32, seconds: Option<f64>) -> Self {
        let at = seconds.map(|s| std::time::Instant::now() + std::time::Duration::from_secs_f64(s));
        let request = ScreenshotRequest {
            after_passes: Some(passes.max(1)).filter(|_| at.is_none()),
            at,
            quit_after: true,
            delay: 0,
            ..ScreenshotRequest::new(path, None)
        };
        Self { request: Some(request), ..Self::default() }
    }

    /// A screenshot the user asked for (see `ScreenshotRequest::asked`).
    pub fn ask(&mut self, path: PathBuf, crop: Option<egui::Rect>) -> Result<(), String> {
        self.request = Some(ScreenshotRequest::asked(path, crop)?);
        Ok(())
    }

    pub fn exit_error(&self) -> Arc<Mutex<Option<String>>> {
        self.exit_error.clone()
    }

    /// Advance one frame; `ready(n)` says whether every pane has n passes.
    pub fn step(&mut self, ctx: &egui::Context, ready: impl Fn(u32) -> bool) -> Option<Captured> {
        let request = self.request.as_mut()?;
        let is_ready = request.after_passes.is_none_or(ready);
        let is_ready = is_ready && request.at.is_none_or(|at| std::time::Instant::now() >= at);
        if let Some(at) = request.at {
            ctx.request_repaint_after(at.saturating_duration_since(std::time::Instant::now()));
        }
        let result = request.step(ctx, is_ready)?;
        let quit = request.quit_after;
        self.request = None;
        if let (Err(e), Ok(mut slot)) = (&result, self.exit_error.lock()) {
            *slot = Some(e.clone());
        }
        Some(Captured { result, quit })
    }
}

/// `--screenshot PATH` checked before the window opens: a PNG, in a folder
/// that exists, not replacing a file GI Studio did not write (unless forced).
pub fn check_screenshot_path(path: &Path, force: bool) -> Result<()> {
    if !matches!(ImageFormat::of(path), Ok(ImageFormat::Png)) {
        bail!("{}: screenshots are PNG files (end the name in .png)", path.display());
    }
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !folder.is_dir() {
        bail!("{}: the folder {} does not exist", path.display(), folder.display());
    }
    if !force && !fileio::replaceable(path, &[SIGNATURE.as_bytes()])? {
        bail!("{}: exists and was not written by GI Studio; pass --force to replace it", path.display());
    }
    Ok(())
}

/// Save `image` (or its `crop`, in points) as a PNG, atomically.
pub fn save_screenshot(
    image: &egui::ColorImage,
    crop: Option<egui::Rect>,
    pixels_per_point: f32,
    path: &Path,
) -> Result<(), String> {
    let [width, height] = image.size;
    let (x0, y0, x1, y1) = match crop {
        Some(rect) => {
            let clamp = |v: f32, max: usize| ((v * pixels_per_point).round().max(0.0) as usize).min(max);
            (clamp(rect.min.x, width), clamp(rect.min.y, height), clamp(rect.max.x, width), clamp(rect.max.y, height))
        }
        None => (0, 0, width, height),
    };
    if x1 <= x0 || y1 <= y0 {
        return Err("nothing to capture".into());
    }
    let mut rgba = Vec::with_capacity((x1 - x0) * (y1 - y0) * 4);
    for y in y0..y1 {
        for x in x0..x1 {
            rgba.extend_from_slice(&image.pixels[y * width + x].to_array());
        }
    }
    save_png(path, (x1 - x0) as u32, (y1 - y0) as u32, true, &rgba).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comparison_sheet_is_the_cropped_region_in_physical_pixels() {
        let (w, h) = (20usize, 16usize);
        let pixels: Vec<egui::Color32> =
            (0..w * h).map(|i| egui::Color32::from_rgb((i % w) as u8, (i / w) as u8, 7)).collect();
        let image = egui::ColorImage { size: [w, h], pixels, source_size: egui::vec2(w as f32, h as f32) };
        let temp = tempfile::tempdir().unwrap();
        let path = temp.path().join("sheet.png");
        // Points at 2 pixels per point: the rect (1, 2)–(5, 5) is pixels (2, 4)–(10, 10)
        let rect = egui::Rect::from_min_max(egui::pos2(1.0, 2.0), egui::pos2(5.0, 5.0));
        save_screenshot(&image, Some(rect), 2.0, &path).unwrap();
        let saved = image::open(&path).unwrap().to_rgba8();
        assert_eq!(saved.dimensions(), (8, 6));
        assert_eq!(saved.get_pixel(0, 0).0, [2, 4, 7, 255]);
        assert_eq!(saved.get_pixel(7, 5).0, [9, 9, 7, 255]);
        assert!(save_screenshot(
            &image,
            Some(egui::Rect::from_min_max(egui::pos2(30.0, 30.0), egui::pos2(40.0, 40.0))),
            1.0,
            &path
        )
        .is_err());
    }

    #[test]
    fn screenshot_paths_are_checked_before_the_window_opens() {
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        assert!(check_screenshot_path(&dir.join("x.jpg"), false).unwrap_err().to_string().contains(".png"));
        assert!(check_screenshot_path(&dir.join("missing/x.png"), false).unwrap_err().to_string().contains("folder"));
        let theirs = dir.join("theirs.png");
        std::fs::write(&theirs, "not ours").unwrap();
        assert!(check_screenshot_path(&theirs, false).unwrap_err().to_string().contains("--force"));
        check_screenshot_path(&theirs, true).unwrap();
        check_screenshot_path(&dir.join("new.png"), false).unwrap();
    }
}
