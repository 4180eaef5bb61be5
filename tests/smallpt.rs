//! smallpt as smallpt renders it: its camera rays start 140 along
//! themselves, and no path leaves its box of radius-1e5 spheres.

mod common;

use std::sync::Arc;

use common::{settings, valid};
use gi_studio::render::{render_blocking, Algorithm, RenderJob};
use gi_studio::scene::{presets, ClipAlong};

/// smallpt's `cam.o + d*140`, with `d` normalised first, starts every ray
/// on a sphere about the eye; on the plane 140 along the view axis the top
/// rows would start above the ceiling (y ≈ 81.9 > 81.6) and look straight
/// into the light (radiance 12). The room's ceiling there is below 1.
#[test]
fn smallpts_top_rows_show_the_ceiling_not_the_light() {
    let scene = presets::preset("smallpt").unwrap().unwrap().into_scene();
    assert_eq!(scene.camera.near_clip_along, ClipAlong::Ray);
    let top_rows_max = |scene| {
        let (image, _) =
            render_blocking(&RenderJob::new(Arc::new(valid(scene)), settings(Algorithm::Path, 512, 384, 16)))
                .expect("renders");
        image.pixels[..3 * 512].iter().flatten().fold(0.0f32, |m, &c| m.max(c))
    };
    let brightest = top_rows_max(scene.clone());
    assert!(brightest <= 3.0, "a top-row pixel at {brightest}");
    // The check can fail: measured on the view axis the light shows
    let mut on_plane = scene;
    on_plane.camera.near_clip_along = ClipAlong::ViewAxis;
    let brightest = top_rows_max(on_plane);
    assert!(brightest >= 10.0, "the light's radiance 12 in the top rows, found {brightest}");
}
