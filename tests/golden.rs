//! Golden images: a hash of every preset rendered by every algorithm at
//! 64×48, 4 spp, a fixed seed. A refactor must leave every hash as it was;
//! an intended change of an image is its own commit, which says why and
//! updates the hash here. (The hashes are of this machine's float
//! arithmetic: x86-64, and the same on any thread count.)

mod common;

use common::valid;
use std::sync::Arc;

use gi_studio::render::{render_blocking, LinearImage, RenderJob, RenderSettings};
use gi_studio::scene::presets;

/// (preset, algorithm, FNV-1a of the image's f32 bits).
const GOLDEN: &[(&str, &str, u64)] = &[
    ("cornell", "whitted", 0x80aa3c0ec2f92365),
    ("cornell", "path", 0xe833e0642c370660),
    ("cornell", "photon", 0x3e7ca4681f1e2767),
    ("cornell", "sppm", 0xabdfaab6eccc921a),
    ("smallpt", "whitted", 0x88fbbc44b9345a5b),
    ("smallpt", "path", 0xce8e33ea0c87c9a0),
    ("smallpt", "photon", 0xb778cd9064e34996),
    ("smallpt", "sppm", 0x029e9bdbe75cdd7d),
    ("thesis", "whitted", 0xf5a083af67f2ead7),
    ("thesis", "path", 0xd3f536b5715689d2),
    ("thesis", "photon", 0xf2087e9c9389e9e3),
    ("thesis", "sppm", 0x0f0703e739352381),
    ("lights", "whitted", 0x0cbf44367ab62662),
    ("lights", "path", 0x90d7148184658b0f),
    ("lights", "photon", 0x71efe51313becae6),
    ("lights", "sppm", 0xcf2fd0515198e408),
    ("caustics", "whitted", 0xb91b2d20a3a39a19),
    ("caustics", "path", 0x254a1bdcdc40f3eb),
    ("caustics", "photon", 0x4cd0fde0f1043e21),
    ("cornell", "photon+final-gather", 0x9a1e720e38ae8db0),
    ("caustics", "sppm", 0x61a9d04d5163d909),
];

pub fn image_hash(image: &LinearImage) -> u64 {
    let words = [image.width, image.height].into_iter().chain(image.pixels.iter().flatten().map(|c| c.to_bits()));
    words.flat_map(u32::to_le_bytes).fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3))
}

fn golden_render(preset: &str, name: &str) -> LinearImage {
    let (algorithm, final_gather) = match name.split_once('+') {
        Some((algorithm, _)) => (algorithm.parse().unwrap(), true),
        None => (name.parse().unwrap(), false),
    };
    let scene = presets::preset(preset).unwrap().unwrap();
    let mut settings = RenderSettings {
        width: 64,
        height: 48,
        samples_per_pixel: Some(4),
        seed: 20_261_201,
        ..RenderSettings::for_algorithm(algorithm)
    };
    settings.set_photons(20_000);
    if let Some(p) = settings.photon_mut() {
        (p.final_gather, p.final_gather_rays) = (final_gather, 4);
    }
    render_blocking(&RenderJob::new(Arc::new(valid(scene)), settings)).unwrap().0
}

#[test]
fn every_preset_and_algorithm_renders_its_golden_image() {
    let mut changed = Vec::new();
    for &(preset, algorithm, expected) in GOLDEN {
        let found = image_hash(&golden_render(preset, algorithm));
        if found != expected {
            changed.push(format!("    (\"{preset}\", \"{algorithm}\", {found:#018x}),"));
        }
    }
    assert!(changed.is_empty(), "images changed; if intended, commit them on their own with:\n{}", changed.join("\n"));
}
