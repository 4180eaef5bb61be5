//! Whatever a file holds or a flag says, the program answers with an error
//! or a render: never a panic, never an allocation without bound. The test
//! runs itself again in a child process under a memory cap (`ulimit -v`),
//! so an unbounded allocation aborts the child and fails the test on any
//! machine, however much memory it has.

mod common;

use common::valid;
use std::path::Path;
use std::process::Command;
use std::sync::Arc;

use clap::Parser;
use gi_studio::cli::{Command as Cli, Headless};
use gi_studio::render::{render_blocking, Algorithm, RenderJob, RenderSettings};
use gi_studio::scene::{parse_scene, presets, ValidScene};
use proptest::prelude::*;

const CHILD: &str = "GI_STUDIO_ROBUSTNESS_CHILD";
const MEMORY_CAP_KIB: u64 = 3 << 20;

/// Run `test` in a child process under the memory cap; in the child, run it.
fn in_capped_child(name: &str, test: impl FnOnce()) {
    if std::env::var_os(CHILD).is_some() {
        test();
        return;
    }
    let exe = std::env::current_exe().unwrap();
    let output = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {MEMORY_CAP_KIB} && exec \"$0\" \"$@\""))
        .arg(exe)
        .args([name, "--exact", "--test-threads=1", "--nocapture"])
        .env(CHILD, "1")
        .output()
        .unwrap();
    let log = format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    assert_eq!(output.status.code(), Some(0), "the capped run failed (a panic, or an abort on memory):\n{log}");
    assert!(log.contains("1 passed"), "the capped run did not run the test:\n{log}");
}

/// Numbers a user or a broken file might write where a number belongs.
const AWKWARD: &[&str] = &[
    "0",
    "-0.0",
    "-1",
    "1e-45",
    "1e-20",
    "1e20",
    "1e38",
    "-1e38",
    "3.5e38",
    "1e400",
    "NaN",
    "inf",
    "-inf",
    "4294967295",
    "18446744073709551615",
    "-4294967296",
    "0.5",
    "2",
    "1e5",
    "65536",
    "16385",
    "1e9",
    "()",
    "\"x\"",
];

/// A fixed seed: the same cases every run (a failure is reproduced by
/// running the test again), each test its own stream.
fn fixed_cases(cases: u32, seed: u64) -> ProptestConfig {
    ProptestConfig {
        cases,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(seed),
        ..ProptestConfig::default()
    }
}

/// The byte ranges of every number in `text`.
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let starts = bytes[at].is_ascii_digit() && (at == 0 || !bytes[at - 1].is_ascii_alphanumeric());
        if starts {
            let end = (at..bytes.len()).find(|&i| !(bytes[i].is_ascii_digit() || b".e-".contains(&bytes[i])));
            let end = end.unwrap_or(bytes.len());
            spans.push((if at > 0 && bytes[at - 1] == b'-' { at - 1 } else { at }, end));
            at = end;
        } else {
            at += 1;
        }
    }
    spans
}

#[derive(Clone, Debug)]
enum Mutation {
    /// Number `which` (modulo their count) replaced by an awkward value.
    Number {
        which: usize,
        value: usize,
    },
    /// Bytes deleted, or random text inserted, at a fraction of the text.
    Delete {
        at: f64,
        length: usize,
    },
    Insert {
        at: f64,
        text: String,
    },
    /// A slice of the text repeated in place.
    Repeat {
        at: f64,
        length: usize,
        times: usize,
    },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (any::<usize>(), 0..AWKWARD.len()).prop_map(|(which, value)| Mutation::Number { which, value }),
        1 => (0.0..1.0, 1..40usize).prop_map(|(at, length)| Mutation::Delete { at, length }),
        1 => (0.0..1.0, "[(),:\"a-z0-9. \\n]{1,12}").prop_map(|(at, text)| Mutation::Insert { at, text }),
        1 => (0.0..1.0, 1..60usize, 2..50usize).prop_map(|(at, length, times)| Mutation::Repeat { at, length, times }),
    ]
}

fn apply(text: &str, mutation: &Mutation) -> String {
    let boundary = |at: f64| {
        let mut i = ((text.len() as f64) * at) as usize;
        while !text.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    let clamp = |i: usize| {
        let mut i = i.min(text.len());
        while !text.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    match mutation {
        Mutation::Number { which, value } => {
            let spans = number_spans(text);
            let (start, end) = spans[which % spans.len()];
            format!("{}{}{}", &text[..start], AWKWARD[*value], &text[end..])
        }
        Mutation::Delete { at, length } => {
            let start = boundary(*at);
            format!("{}{}", &text[..start], &text[clamp(start + length)..])
        }
        Mutation::Insert { at, text: inserted } => {
            let start = boundary(*at);
            format!("{}{inserted}{}", &text[..start], &text[start..])
        }
        Mutation::Repeat { at, length, times } => {
            let start = boundary(*at);
            let slice = &text[start..clamp(start + length)];
            format!("{}{}{}", &text[..start], slice.repeat(*times), &text[start..])
        }
    }
}

/// A scene that loads renders: a tiny image, finite and not negative.
fn render_tiny(scene: ValidScene, algorithm: Algorithm) {
    let mut settings =
        RenderSettings { width: 8, height: 6, samples_per_pixel: Some(1), ..RenderSettings::for_algorithm(algorithm) };
    settings.set_photons(200);
    let (image, _) = render_blocking(&RenderJob::new(Arc::new(valid(scene)), settings)).expect("a valid scene renders");
    assert!(image.pixels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0), "{algorithm}");
}

#[test]
fn any_scene_text_loads_or_is_refused_and_what_loads_renders() {
    in_capped_child("any_scene_text_loads_or_is_refused_and_what_loads_renders", || {
        let presets: Vec<&str> = presets::PRESETS.iter().map(|(_, text)| *text).collect();
        let rendered = std::sync::atomic::AtomicUsize::new(0);
        let cases = 1500;
        proptest!(fixed_cases(cases, 1), |(preset in 0..presets.len(), mutations in prop::collection::vec(mutation(), 1..4),
                            algorithm in 0..4usize)| {
            let text = mutations.iter().fold(presets[preset].to_owned(), |t, m| apply(&t, m));
            if let Ok(scene) = parse_scene(&text, Path::new("mutated.ron")) {
                render_tiny(scene, Algorithm::ALL[algorithm]);
                rendered.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
        });
        // Enough mutants load to exercise the renderers, not only the parser
        let rendered = rendered.into_inner();
        println!("{rendered} of {cases} mutated presets loaded and rendered");
        assert!(rendered > cases as usize / 20, "only {rendered} of {cases} mutants loaded");
        proptest!(fixed_cases(2000, 2), |(bytes in prop::collection::vec(any::<u8>(), 0..2048))| {
            let text = String::from_utf8_lossy(&bytes);
            let _ = parse_scene(&text, Path::new("random.ron"));
        });
    });
}

fn flag() -> impl Strategy<Value = (&'static str, String)> {
    let flags = prop::sample::select(vec![
        "--spp",
        "--time",
        "--width",
        "--height",
        "--seed",
        "--threads",
        "--max-depth",
        "--exposure",
        "--clamp",
        "--global-photons",
        "--caustic-photons",
        "--k",
        "--max-radius",
        "--gather-rays",
        "--sppm-photons",
        "--sppm-radius",
        "--sppm-alpha",
    ]);
    let value = prop_oneof![
        prop::sample::select(AWKWARD.to_vec()).prop_map(str::to_owned),
        any::<i64>().prop_map(|v| v.to_string()),
        any::<f64>().prop_map(|v| v.to_string()),
        any::<u32>().prop_map(|v| v.to_string()),
        // Near the limits, where an off-by-one would let a value through
        (0u32..40_000).prop_map(|v| v.to_string()),
        (-2.0f64..70.0).prop_map(|v| v.to_string()),
    ];
    (flags, value)
}

/// Whatever flags are given, the settings they make are refused or within
/// every limit (`RenderSettings::problems`): no size, thread count or photon
/// count a user types gets past the parser unbounded.
#[test]
fn any_flags_give_an_error_or_settings_within_limits() {
    in_capped_child("any_flags_give_an_error_or_settings_within_limits", || {
        let scene = presets::preset("cornell").unwrap().unwrap();
        let accepted = std::sync::atomic::AtomicUsize::new(0);
        let algorithms = prop::sample::select(vec!["whitted", "path", "photon", "sppm"]);
        proptest!(fixed_cases(3000, 3), |(flags in prop::collection::vec(flag(), 1..6), algorithm in algorithms)| {
            let mut argv = vec!["gi-studio".to_owned(), "render".into(), "x.ron".into(), "-o".into(), "x.png".into()];
            argv.push(format!("--algo={algorithm}"));
            for (flag, value) in &flags {
                argv.push(format!("{flag}={value}"));
            }
            let Ok(Headless { command: Cli::Render(args) }) = Headless::try_parse_from(&argv) else {
                return Ok(());
            };
            if let Ok(settings) = args.flags.settings(&scene) {
                prop_assert_eq!(settings.problems(), vec![]);
                prop_assert!(settings.width as u64 * settings.height as u64 <= gi_studio::limits::IMAGE_PIXELS);
                prop_assert!(args.flags.threads <= gi_studio::limits::THREADS.max);
                accepted.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
        });
        let accepted = accepted.into_inner();
        println!("{accepted} of 3000 random flag sets accepted");
        assert!(accepted > 100, "only {accepted} flag sets were accepted: the limits went untested");
    });
}

/// Random bytes as a photon map: refused, never a panic or a huge allocation.
#[test]
fn any_bytes_as_a_photon_map_are_refused() {
    in_capped_child("any_bytes_as_a_photon_map_are_refused", || {
        let dir =
            std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("gi-robust-pmap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("random.pmap");
        proptest!(fixed_cases(500, 4), |(tail in prop::collection::vec(any::<u8>(), 0..400), keep_magic in any::<bool>())| {
            // With the header of a map for scene key 1 and settings key 2, the
            // random part reaches the counts, the photons and the checksum
            let mut bytes = Vec::new();
            if keep_magic {
                bytes.extend(b"GIPHOTON");
                bytes.extend(3u32.to_le_bytes());
                bytes.extend(1u64.to_le_bytes());
                bytes.extend(2u64.to_le_bytes());
            }
            bytes.extend(tail);
            std::fs::write(&path, &bytes).unwrap();
            prop_assert!(gi_studio::render::integrators::photon_map::file::load_photon_maps(&path, 1, 2).is_err());
        });
    });
}
