//! Renders split into shards and merged: the merge is the one-process
//! render (to the order of summation, exactly for one shard), the merge
//! refuses parts that do not belong together, and the farm's scripts say
//! what a cluster must run.

mod common;

use std::path::PathBuf;
use std::process::Command;
use std::sync::Arc;

use common::*;
use gi_studio::analysis::metrics::{rel_mse, RelMseOptions};
use gi_studio::cli::shard::{merge, Partial, ShardManifest, ShardSpec};
use gi_studio::render::{Algorithm, LinearImage, RenderEvent, RenderJob, RenderSession, RenderSettings, Workers};
use gi_studio::scene::{presets, Scene};

/// A render's image and its odd passes' mean.
fn render_with_halves(scene: &Scene, settings: RenderSettings) -> (LinearImage, Option<LinearImage>) {
    let session = RenderSession::new(Workers::shared().unwrap(), None).unwrap();
    let generation = session.start(RenderJob::new(Arc::new(valid(scene.clone())), settings));
    for event in session.events().iter() {
        match event {
            RenderEvent::Finished { generation: g, image, odd, .. } if g == generation => {
                return ((*image).clone(), odd.map(|o| (*o).clone()));
            }
            RenderEvent::Failed { message, .. } => panic!("{message}"),
            _ => {}
        }
    }
    panic!("no image")
}

/// Shard `spec` of `whole`, as `render --shard` makes it.
fn shard(scene: &Scene, whole: &RenderSettings, spec: ShardSpec) -> (PathBuf, Partial) {
    let (mean, odd) = render_with_halves(scene, spec.settings(whole).unwrap());
    let manifest = ShardManifest::new(scene, "cornell.ron", whole, spec, 1.0 + spec.index as f64);
    (PathBuf::from(format!("part-{}.exr", spec.index)), Partial { mean, odd, manifest })
}

/// K = 1, 3, 4 and 7 shards of 12 passes, path tracing and Whitted: merged,
/// the one-process render — bit for bit for one shard, to relMSE 1e-9 for
/// more (sums in another order); the merged variance is the film's.
#[test]
fn shards_merge_to_the_render_they_split() {
    let scene = presets::preset("cornell").unwrap().unwrap().into_scene();
    for algorithm in [Algorithm::Path, Algorithm::Whitted] {
        let whole = settings(algorithm, 32, 24, 12);
        let (single, single_odd) = render_with_halves(&scene, whole.clone());
        for count in [1, 3, 4, 7] {
            let parts: Vec<_> = (0..count).map(|index| shard(&scene, &whole, ShardSpec { index, count })).collect();
            let merged = merge(&parts, true).unwrap();
            assert_eq!(merged.passes, 12);
            assert_eq!(merged.slowest, (count - 1, count as f64));
            if count == 1 {
                assert!(merged.image.pixels == single.pixels, "{algorithm}: one shard is the render itself");
            }
            let error = rel_mse(&merged.image, &single, RelMseOptions::default()).unwrap();
            assert!(error < 1e-9, "{algorithm}, {count} shards: relMSE {error:e} against the single render");
            if algorithm == Algorithm::Path {
                // The merged halves give the variance the film would
                let film = render_variance(&scene, &whole);
                let variance = merged.variance.as_ref().expect("a variance");
                if count == 1 || count == 3 {
                    // Shards of an even number of passes, each starting on an even one, keep the film's halves
                    let error = rel_mse(variance, &film, RelMseOptions::default()).unwrap();
                    assert!(error < 1e-9, "{count} shards: the variance differs ({error:e})");
                }
                assert!(single_odd.is_some());
            }
        }
    }
}

fn render_variance(scene: &Scene, settings: &RenderSettings) -> LinearImage {
    let session = RenderSession::new(Workers::shared().unwrap(), None).unwrap();
    let generation = session.start(RenderJob::new(Arc::new(valid(scene.clone())), settings.clone()));
    for event in session.events().iter() {
        if let RenderEvent::Finished { generation: g, variance, .. } = event {
            if g == generation {
                return (*variance.expect("a path tracer keeps halves")).clone();
            }
        }
    }
    panic!("no image")
}

/// Parts that do not belong together are refused, each saying why: one of
/// another scene, another seed, a missing shard, the same shard twice.
#[test]
fn merging_refuses_foreign_missing_and_duplicate_parts() {
    let scene = presets::preset("cornell").unwrap().unwrap().into_scene();
    let whole = settings(Algorithm::Whitted, 16, 12, 4);
    let parts: Vec<_> = (0..4).map(|index| shard(&scene, &whole, ShardSpec { index, count: 4 })).collect();
    let message = |parts: &[(PathBuf, Partial)]| merge(parts, true).err().expect("refused").to_string();

    let mut foreign = parts.clone();
    foreign[2].1.manifest.scene_key = "0123456789abcdef".into();
    assert!(message(&foreign).contains("part-2.exr: from another render than part-0.exr (its scene differs)"));
    let mut reseeded = parts.clone();
    reseeded[1].1.manifest.seed += 1;
    assert!(message(&reseeded).contains("(its seed differs)"));
    let mut retuned = parts.clone();
    retuned[3].1.manifest.settings_key = "fedcba9876543210".into();
    assert!(message(&retuned).contains("(its settings differ)"), "{}", message(&retuned));
    let missing = [parts[0].clone(), parts[1].clone(), parts[3].clone()];
    assert!(message(&missing).contains("shard 2 of 4 is missing"), "{}", message(&missing));
    assert!(message(&[parts[0].clone(), parts[3].clone()]).contains("shards 1, 2 of 4 are missing"));
    assert!(merge(&missing, false).is_ok(), "--partial merges what there is");
    let twice = [parts[0].clone(), parts[1].clone(), parts[1].clone(), parts[3].clone()];
    assert!(message(&twice).contains("part-1.exr and part-1.exr are both shard 1/4"));
    let mut moved = parts.clone();
    moved[3].1.manifest.first_pass = 0;
    assert!(message(&moved).contains("its manifest's passes are not shard 3/4's"));
}

/// A partial comes back as it was saved, manifest and all; shard specs parse
/// and refuse what is not one.
#[test]
fn a_partial_round_trips_and_shard_specs_are_checked() {
    let scene = presets::preset("cornell").unwrap().unwrap().into_scene();
    let whole = settings(Algorithm::Path, 16, 12, 6);
    let (_, part) = shard(&scene, &whole, ShardSpec { index: 1, count: 3 });
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("part.exr");
    part.save(&path).unwrap();
    assert_eq!(Partial::load(&path).unwrap(), part);
    assert_eq!((part.manifest.first_pass, part.manifest.passes), (2, 2));
    assert_eq!("3/8".parse::<ShardSpec>(), Ok(ShardSpec { index: 3, count: 8 }));
    for bad in ["8/8", "1", "a/2", "0/0", "-1/4"] {
        assert!(bad.parse::<ShardSpec>().is_err(), "{bad}");
    }
}

/// SPPM's passes build on each other: each shard is a run of its own, the
/// first with the render's own seed (so one shard is the render), the rest
/// with seeds of their own; merged, the runs weigh by their passes.
#[test]
fn dependent_passes_shard_as_independent_runs() {
    let scene = presets::preset("cornell").unwrap().unwrap().into_scene();
    let mut whole = settings(Algorithm::Sppm, 16, 12, 4);
    whole.set_photons(5_000);
    let first = ShardSpec { index: 0, count: 2 }.settings(&whole).unwrap();
    let second = ShardSpec { index: 1, count: 2 }.settings(&whole).unwrap();
    assert_eq!((first.first_pass, second.first_pass), (0, 0));
    assert_eq!(first.seed, whole.seed);
    assert_ne!(second.seed, whole.seed);
    let parts: Vec<_> = (0..2).map(|index| shard(&scene, &whole, ShardSpec { index, count: 2 })).collect();
    let merged = merge(&parts, true).unwrap();
    assert!(merged.variance.is_none());
    let channels = |image: &LinearImage| image.pixels.iter().flatten().map(|c| *c as f64).collect::<Vec<f64>>();
    let (a, b) = (channels(&parts[0].1.mean), channels(&parts[1].1.mean));
    for (i, merged) in channels(&merged.image).into_iter().enumerate() {
        let mean = (a[i] + b[i]) / 2.0;
        assert!((merged - mean).abs() <= 1e-6 * mean.abs().max(1e-3), "channel {i}: {merged} vs {mean}");
    }
}

/// The commands a user types: `render --shard` twice, `merge`, `compare`
/// with the one-process render; `farm slurm` writes an array job, a merge
/// job after it and the script that submits both.
#[test]
fn the_commands_shard_merge_and_write_the_farms_scripts() {
    let bin = env!("CARGO_BIN_EXE_gi-studio");
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = format!("{}/assets/scenes/cornell.ron", env!("CARGO_MANIFEST_DIR"));
    let run = |args: &[&str]| {
        let out = Command::new(bin).args(args).current_dir(d).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
        (out.status.code(), text)
    };
    let flags = ["--algo", "path", "--spp", "6", "--width", "24", "--height", "18"];
    let (code, text) = run(&[&["render", &scene, "-o", "whole.exr"][..], &flags].concat());
    assert_eq!(code, Some(0), "{text}");
    for shard in ["0/2", "1/2"] {
        let part = format!("part-{}.exr", &shard[..1]);
        let (code, text) = run(&[&["render", &scene, "-o", &part, "--shard", shard][..], &flags].concat());
        assert_eq!(code, Some(0), "{text}");
        assert!(text.contains(&format!("shard {shard}: passes")), "{text}");
        assert!(d.join(format!("{part}.shard.ron")).exists());
    }
    let (code, text) = run(&["merge", "part-0.exr", "part-1.exr", "-o", "merged.exr"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("merged 2 of 2 shards") && text.contains("6 samples per pixel"), "{text}");
    let (code, text) = run(&["compare", "merged.exr", "whole.exr", "--max-rel-mse", "1e-9"]);
    assert_eq!(code, Some(0), "{text}");
    // Images of other sizes are refused, each size as width×height
    let (code, text) = run(&["render", &scene, "-o", "small.exr", "--spp", "1", "--width", "8", "--height", "4"]);
    assert_eq!(code, Some(0), "{text}");
    let (code, text) = run(&["compare", "small.exr", "whole.exr"]);
    assert_eq!(code, Some(1), "{text}");
    assert!(text.contains("small.exr is 8×4 and") && text.contains("whole.exr is 24×18"), "{text}");
    let (code, text) = run(&["merge", "part-0.exr", "-o", "half.exr"]);
    assert_eq!((code, text.contains("shard 1 of 2 is missing")), (Some(1), true), "{text}");
    let (code, text) = run(&["render", &scene, "-o", "x.exr", "--shard", "0/2", "--time", "1"]);
    assert_eq!((code, text.contains("--shard needs --spp")), (Some(1), true), "{text}");

    let farm = d.join("farm");
    let farm_s = farm.display().to_string();
    let (code, text) =
        run(&["farm", "slurm", &scene, "--shards", "4", "--out", &farm_s, "--", "--algo", "path", "--spp", "8"]);
    assert_eq!(code, Some(0), "{text}");
    let render = std::fs::read_to_string(farm.join("render.sbatch")).unwrap();
    assert!(
        render.contains("#SBATCH --array=0-3") && render.contains("--shard \"$SLURM_ARRAY_TASK_ID/4\""),
        "{render}"
    );
    assert!(render.contains(bin) && render.contains("'--spp' '8'"), "{render}");
    let submit = std::fs::read_to_string(farm.join("submit.sh")).unwrap();
    assert!(submit.contains("--dependency=afterok:") && submit.contains("merge.sbatch"), "{submit}");
    assert!(std::fs::read_to_string(farm.join("merge.sbatch")).unwrap().contains(" merge "));
    assert!(std::fs::read_to_string(farm.join("scene.ron")).unwrap().contains("panel a"));
    let (code, text) = run(&["farm", "k8s", &scene, "--shards", "3", "--out", &farm_s, "--", "--spp", "6"]);
    assert_eq!(code, Some(0), "{text}");
    let job = std::fs::read_to_string(farm.join("render-job.yaml")).unwrap();
    assert!(job.contains("completionMode: Indexed") && job.contains("completions: 3"), "{job}");
    assert!(job.contains("$JOB_COMPLETION_INDEX/3"), "{job}");
    let (code, text) = run(&["farm", "slurm", &scene, "--shards", "9", "--out", &farm_s, "--", "--spp", "8"]);
    assert_eq!((code, text.contains("9 shards of 8 passes")), (Some(1), true), "{text}");
}

/// A reference rendered on a farm serves the studio and `bench`: shards at
/// the reference's size (half the scene's), merged with `--reference`, are
/// the reference `bench` measures an edited scene against, from another
/// folder, where without it `bench` refuses.
#[test]
fn a_merged_reference_is_the_one_bench_measures_against() {
    let bin = env!("CARGO_BIN_EXE_gi-studio");
    let dir = tempfile::tempdir().unwrap();
    let (d, cache) = (dir.path(), dir.path().join("cache"));
    let elsewhere = tempfile::tempdir().unwrap();
    let edited =
        include_str!("../assets/scenes/cornell.ron").replace("width: 640, height: 480", "width: 64, height: 48");
    std::fs::write(d.join("edited.ron"), edited).unwrap();
    let scene = d.join("edited.ron").display().to_string();
    let run = |args: &[&str], at: &std::path::Path| {
        let out = Command::new(bin).args(args).current_dir(at).env("XDG_CACHE_HOME", &cache).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
        (out.status.code(), text)
    };
    let bench = ["bench", &scene, "--budget", "0.05", "--algos", "path", "--reference-budget", "0", "--out", "bench"];
    let (code, text) = run(&bench, elsewhere.path());
    assert_eq!((code, text.contains("no reference for")), (Some(1), true), "{text}");
    // The Cornell box's reference method: light comes through glass
    let flags = ["--algo", "bdpt", "--spp", "16", "--width", "32", "--height", "24"];
    for shard in ["0/2", "1/2"] {
        let part = format!("part-{}.exr", &shard[..1]);
        let (code, text) = run(&[&["render", &scene, "-o", &part, "--shard", shard][..], &flags].concat(), d);
        assert_eq!(code, Some(0), "{text}");
    }
    let (code, text) = run(&["merge", "part-0.exr", "part-1.exr", "--reference"], d);
    assert_eq!((code, text.contains("kept as the reference of")), (Some(0), true), "{text}");
    let (code, text) = run(&bench, elsewhere.path());
    assert_eq!(code, Some(0), "{text}");
    let csv = std::fs::read_to_string(elsewhere.path().join("bench").join("convergence.csv")).unwrap();
    let relmse: Vec<f64> = csv.lines().skip(1).map(|line| line.split(',').nth(5).unwrap().parse().unwrap()).collect();
    assert!(!relmse.is_empty() && relmse.iter().all(|e| e.is_finite()), "{csv}");
}
