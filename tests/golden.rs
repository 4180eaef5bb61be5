//! Golden images: a hash of every preset rendered by every algorithm at
//! 64×48, 4 spp, a fixed seed. A refactor must leave every hash as it was;
//! an intended change of an image is its own commit, which says why and
//! updates the hash here. (The hashes are of this machine's float
//! arithmetic: x86-64, and the same on any thread count.)

mod common;

use common::valid;
use std::sync::Arc;

use gi_studio::render::{render_blocking, LinearImage, Method, RenderJob, RenderSettings};
use gi_studio::scene::presets;

/// (preset, algorithm, FNV-1a of the image's f32 bits).
const GOLDEN: &[(&str, &str, u64)] = &[
    ("cornell", "whitted", 0x80aa3c0ec2f92365),
    ("cornell", "path", 0x2f882b069bbc2cc9),
    ("cornell", "photon", 0x3e7ca4681f1e2767),
    ("cornell", "sppm", 0x12cfbeae302927cf),
    ("smallpt", "whitted", 0x88fbbc44b9345a5b),
    ("smallpt", "path", 0xce8e33ea0c87c9a0),
    ("smallpt", "photon", 0xb778cd9064e34996),
    ("smallpt", "sppm", 0x35d8b83641bc8090),
    ("thesis", "whitted", 0xf5a083af67f2ead7),
    ("thesis", "path", 0xd3f536b5715689d2),
    ("thesis", "photon", 0x45aa5ba8d47e2c4c),
    ("thesis", "sppm", 0x5e3424bbb9013d2b),
    ("lights", "whitted", 0x0cbf44367ab62662),
    ("lights", "path", 0x90d7148184658b0f),
    ("lights", "photon", 0xb97335c3222a3f68),
    ("lights", "sppm", 0x5ffc2ddc41000170),
    ("caustics", "whitted", 0xcade06c70e592ae9),
    ("caustics", "path", 0xf24832964be14579),
    ("caustics", "photon", 0x34052dd50a24050d),
    ("cornell", "photon+final-gather", 0x9a1e720e38ae8db0),
    ("caustics", "sppm", 0xe9ab48abc8900dac),
    ("cornell", "lt", 0x9759665f475ad177),
    ("cornell", "bdpt", 0xb3a8252a050a03bd),
    ("cornell", "bpm", 0x5fc2df9477771230),
    ("cornell", "vcm", 0x3d695e85348ca315),
    ("smallpt", "lt", 0xc809727425375075),
    ("smallpt", "bdpt", 0xeb0bae7dafa5fa4a),
    ("smallpt", "bpm", 0x4846a6e7899f2fd5),
    ("smallpt", "vcm", 0x2a5885756d3d9315),
    ("thesis", "lt", 0x9b5062221dd89d73),
    ("thesis", "bdpt", 0xdf38140b2f029eec),
    ("thesis", "bpm", 0x7b50941d5fc0e1d2),
    ("thesis", "vcm", 0x0c95571894c0b01c),
    ("lights", "lt", 0x2086e3d9e2c5a0d7),
    ("lights", "bdpt", 0xf3e1c1701854d12d),
    ("lights", "bpm", 0x8edabdadaa63cfd6),
    ("lights", "vcm", 0xf3e1c1701854d12d),
    ("caustics", "lt", 0xf3b6b05f01fd2c0e),
    ("caustics", "bdpt", 0x46be6ee4177d1dd0),
    ("caustics", "bpm", 0xa7fd24578afde5bb),
    ("caustics", "vcm", 0xb4555fcf43486646),
    ("mirror-caustic", "whitted", 0x64dde4973d71bdb1),
    ("mirror-caustic", "path", 0x7ce42b5817d63f7b),
    ("mirror-caustic", "photon", 0x15537020ad47320a),
    ("mirror-caustic", "sppm", 0x2dc472c61e775a4d),
    ("mirror-caustic", "lt", 0xb4c07f387dca1d23),
    ("mirror-caustic", "bdpt", 0x1e424ad4c5b0981c),
    ("mirror-caustic", "bpm", 0x70f80bee3c80aeb4),
    ("mirror-caustic", "vcm", 0xf774a43f6ff22d66),
    ("gap-room", "whitted", 0x9321fe4d8b9dc36b),
    ("gap-room", "path", 0x5a83894b7f96d9d4),
    ("gap-room", "photon", 0x8f006686cd92292b),
    ("gap-room", "sppm", 0xf05ebee196baff16),
    ("gap-room", "lt", 0x2acffbfe6536790e),
    ("gap-room", "bdpt", 0x1c274efc77609cc8),
    ("gap-room", "bpm", 0x7766370b40aa03f3),
    ("gap-room", "vcm", 0x1c274efc77609cc8),
    ("glossy", "whitted", 0x43502b2763536f51),
    ("glossy", "path", 0x31cf02251c8aa710),
    ("glossy", "photon", 0xa2a568680680ec5f),
    ("glossy", "sppm", 0xa46543b930045a62),
    ("glossy", "lt", 0xf581567eb7216c10),
    ("glossy", "bdpt", 0x3af334f206b3eb9b),
    ("glossy", "bpm", 0x35f6f40d372672f9),
    ("glossy", "vcm", 0x3af334f206b3eb9b),
    ("metals", "whitted", 0x6ac148cf7b066693),
    ("metals", "path", 0xbac0ab3b42e86a0e),
    ("metals", "photon", 0xcbef8e81fb8c360e),
    ("metals", "sppm", 0x2f4db4a4f2a6c632),
    ("metals", "lt", 0x0a2cff20c61e8340),
    ("metals", "bdpt", 0x188ff45aa7284e93),
    ("metals", "bpm", 0x2ea1c41abb573fd6),
    ("metals", "vcm", 0x188ff45aa7284e93),
    ("cornell", "vcm+everywhere", 0x1b195b7b4ffa81a9),
    ("smallpt", "vcm+everywhere", 0xe02f1f9239cdf1cd),
    ("thesis", "vcm+everywhere", 0xc4fc44659adbf1dd),
    ("lights", "vcm+everywhere", 0xdabb2466ab1a31cf),
    ("caustics", "vcm+everywhere", 0xd887eeec1da6e224),
    ("mirror-caustic", "vcm+everywhere", 0xa9b3a4fe8e0ceb20),
    ("gap-room", "vcm+everywhere", 0xae39874d96921092),
    ("glossy", "vcm+everywhere", 0x74cd4f4fe0275727),
    ("metals", "vcm+everywhere", 0x34a9db20195cc7ca),
    ("cornell-mesh", "whitted", 0x793e1f46ea6e7596),
    ("cornell-mesh", "path", 0x58de9c52620db98a),
    ("cornell-mesh", "photon", 0x3767748a5681c0e3),
    ("cornell-mesh", "sppm", 0x23f2fe30ca074451),
    ("cornell-mesh", "lt", 0x29afcd736a0f4d39),
    ("cornell-mesh", "bdpt", 0x68c2912cef1636b8),
    ("cornell-mesh", "bpm", 0x6673bf8777007beb),
    ("cornell-mesh", "vcm", 0xa9ca71693ee02091),
    ("cornell-mesh", "vcm+everywhere", 0xd6ce817d17944a3f),
    ("knot", "whitted", 0x94cb59d1a530f627),
    ("knot", "path", 0x5966db38feedc0ac),
    ("knot", "photon", 0x31aa840f4fd776f0),
    ("knot", "sppm", 0xc5d6023767ba9043),
    ("knot", "lt", 0xf0a3bf204847d82f),
    ("knot", "bdpt", 0xf0db2c76fb2aeadb),
    ("knot", "bpm", 0x0bddd4483ccbf9ed),
    ("knot", "vcm", 0xf0db2c76fb2aeadb),
    ("knot", "vcm+everywhere", 0xe88b5982d50d0c12),
];

pub fn image_hash(image: &LinearImage) -> u64 {
    let words = [image.width, image.height].into_iter().chain(image.pixels.iter().flatten().map(|c| c.to_bits()));
    words.flat_map(u32::to_le_bytes).fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3))
}

/// `name` is an algorithm, with `+final-gather` (photon mapping) or
/// `+everywhere` (VCM merging everywhere, not only on caustic paths) after it.
fn golden_render(preset: &str, name: &str) -> LinearImage {
    let (algorithm, variant) = name.split_once('+').unwrap_or((name, ""));
    let algorithm = algorithm.parse().unwrap();
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
        (p.final_gather, p.final_gather_rays) = (variant == "final-gather", 4);
    }
    if let Method::Vcm(m) = &mut settings.method {
        m.caustic_merges &= variant != "everywhere";
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

/// Where no light passes a mirror or glass (lights, gap-room, glossy,
/// metals, knot), VCM
/// (merging on caustic paths only) has no merge to make and weighs every
/// connection as BDPT does: its image is BDPT's, bit for bit. A merge's
/// share left in any connection's weight would darken it.
#[test]
fn caustic_merges_without_mirrors_or_glass_are_bdpt() {
    for preset in ["lights", "gap-room", "glossy", "metals", "knot"] {
        let (vcm, bdpt) = (golden_render(preset, "vcm"), golden_render(preset, "bdpt"));
        assert!(vcm.pixels == bdpt.pixels, "{preset}: VCM with caustic merges is not BDPT");
    }
}
