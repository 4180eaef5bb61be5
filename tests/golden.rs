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
    ("thesis", "whitted", 0x94cda340e9029fbf),
    ("thesis", "path", 0xd4c903789d784b5e),
    ("thesis", "photon", 0x271c67c45d9602e2),
    ("thesis", "sppm", 0x76277bb071feeac9),
    ("lights", "whitted", 0x0f9655644c5a1749),
    ("lights", "path", 0x224d3f0577bd0f85),
    ("lights", "photon", 0xdf94a60579cd8b79),
    ("lights", "sppm", 0xda4722b18a112ae2),
    ("caustics", "whitted", 0xb91b2d20a3a39a19),
    ("caustics", "path", 0x254a1bdcdc40f3eb),
    ("caustics", "photon", 0x4cd0fde0f1043e21),
    ("cornell", "photon+final-gather", 0x9a1e720e38ae8db0),
    ("caustics", "sppm", 0x61a9d04d5163d909),
    ("cornell", "lt", 0x9759665f475ad177),
    ("cornell", "bdpt", 0x8a6ef42b2847c36c),
    ("cornell", "bpm", 0xe9ea8713b3894857),
    ("cornell", "vcm", 0x89fbe7deffcd756b),
    ("smallpt", "lt", 0xc809727425375075),
    ("smallpt", "bdpt", 0xeb0bae7dafa5fa4a),
    ("smallpt", "bpm", 0x2ae1a8f0adafeecb),
    ("smallpt", "vcm", 0xe02f1f9239cdf1cd),
    ("thesis", "lt", 0x55dadf5842731070),
    ("thesis", "bdpt", 0x908aa12bc623d296),
    ("thesis", "bpm", 0xc77796a04b294b70),
    ("thesis", "vcm", 0xa5a8cf3bf6e32a00),
    ("lights", "lt", 0xef8ad5f0eae9c7e0),
    ("lights", "bdpt", 0x090643d102d8e985),
    ("lights", "bpm", 0x94ed54d5cae606db),
    ("lights", "vcm", 0x08735ac0e6462041),
    ("caustics", "lt", 0xf3b6b05f01fd2c0e),
    ("caustics", "bdpt", 0x569cb711ea4843a9),
    ("caustics", "bpm", 0xa7fd24578afde5bb),
    ("caustics", "vcm", 0xe756637013ee16a0),
    ("mirror-caustic", "whitted", 0x1450f7364d3087a9),
    ("mirror-caustic", "path", 0xd78be09000dec524),
    ("mirror-caustic", "photon", 0xe39cf090e4cd9961),
    ("mirror-caustic", "sppm", 0x166fd6c60b215de4),
    ("mirror-caustic", "lt", 0xe4fc8ba3b016a676),
    ("mirror-caustic", "bdpt", 0x993efd3de03b6336),
    ("mirror-caustic", "bpm", 0x8b346cd1a6906c9f),
    ("mirror-caustic", "vcm", 0x225a6ae73515bdf1),
    ("gap-room", "whitted", 0x155e05662ff112c4),
    ("gap-room", "path", 0x5e13e65d1b3833b2),
    ("gap-room", "photon", 0xd2339827e09f6b81),
    ("gap-room", "sppm", 0x4cf30debef9d94f3),
    ("gap-room", "lt", 0x884b5aca900d5294),
    ("gap-room", "bdpt", 0xa4268f4621a3b6ed),
    ("gap-room", "bpm", 0xaa5f033e408ad8b6),
    ("gap-room", "vcm", 0x8f3360c39f843519),
    ("glossy", "whitted", 0xe4e8e938ffb3bcba),
    ("glossy", "path", 0xdc244464f46eb8a5),
    ("glossy", "photon", 0x41f3ee01cb971bb9),
    ("glossy", "sppm", 0xd5ee424586d4f304),
    ("glossy", "lt", 0x7a314a76ddd7b30f),
    ("glossy", "bdpt", 0x1bf72d19c28ce512),
    ("glossy", "bpm", 0xe4cdfbbfc50f0661),
    ("glossy", "vcm", 0xab45db97682ee81f),
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
