//! The headless binary as a user runs it. Every run is under a memory cap
//! (`ulimit -v`), so a value that allocates without bound fails here as it
//! would on any machine, instead of passing on a big one; exit codes are
//! checked exactly (1: refused, 2: a bad flag), so a panic (101) or an
//! abort (a signal) never passes for a refusal.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Virtual memory each run may use, in KiB: well above what these renders
/// need, far below what any unbounded value asks for.
const MEMORY_CAP_KIB: u64 = 4 << 20;

fn gi_studio() -> Command {
    capped("")
}

/// gi-studio run by `sh` under the memory cap, after `setup` (more limits).
fn capped(setup: &str) -> Command {
    let mut command = Command::new("sh");
    command
        .arg("-c")
        .arg(format!("{setup} ulimit -v {MEMORY_CAP_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_gi-studio"))
        .env("NO_COLOR", "1");
    command
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("gi-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The run ended with exactly `code` (not a signal, not a panic).
fn assert_exit(output: &Output, code: i32) {
    assert_eq!(output.status.code(), Some(code), "stdout:\n{}\nstderr:\n{}", stdout(output), stderr(output));
}

/// The number just before the first `phrase` in `text` ("… 0 non-finite …").
fn number_before(text: &str, phrase: &str) -> f64 {
    let at = text.find(&format!(" {phrase}")).unwrap_or_else(|| panic!("no {phrase:?} in {text}"));
    let word = text[..at].split_whitespace().last().unwrap_or_default();
    word.trim_start_matches('[').parse().unwrap_or_else(|_| panic!("no number before {phrase:?} in {text}"))
}

/// The files in `dir`, sorted (a failed write must leave no partial file).
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

fn cornell_copy(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, include_str!("../assets/scenes/cornell.ron")).unwrap();
    path
}

const SMALL: [&str; 6] = ["--spp", "2", "--width", "40", "--height", "30"];

#[test]
fn render_writes_png_and_exr_and_prints_a_summary() {
    let dir = temp_dir("ok");
    for (algo, file) in [("path", "a.png"), ("whitted", "b.exr")] {
        let out = dir.join(file);
        let output = gi_studio()
            .args(["render", "assets/scenes/cornell.ron", "--algo", algo])
            .args(SMALL)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert_exit(&output, 0);
        let summary = stdout(&output);
        let words: Vec<&str> = summary.split_whitespace().collect();
        assert_eq!(words[..2], ["40×30", algo], "{summary}");
        assert_eq!(number_before(&summary, "spp"), 2.0, "{summary}");
        assert!(number_before(&summary, "M samples/s") > 0.0 && number_before(&summary, "M rays/s") > 0.0, "{summary}");
        assert_eq!(number_before(&summary, "non-finite"), 0.0, "{summary}");
        let image = gi_studio::render::LinearImage::load(&out).unwrap();
        assert_eq!((image.width, image.height), (40, 30));
        // Rendering again replaces the program's own output
        assert_exit(
            &gi_studio()
                .args(["render", "assets/scenes/cornell.ron", "--algo", algo])
                .args(SMALL)
                .arg("-o")
                .arg(&out)
                .output()
                .unwrap(),
            0,
        );
    }
}

#[test]
fn broken_scene_exits_non_zero_naming_file_line_and_field_without_writing() {
    let dir = temp_dir("broken");
    let scene = dir.join("broken.ron");
    let text = include_str!("../assets/scenes/cornell.ron").replacen("radius: 0.35", "radius: -1.0", 1);
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("never.png");
    let output = gi_studio().arg("render").arg(&scene).arg("-o").arg(&out).output().unwrap();
    assert_exit(&output, 1);
    let stderr = stderr(&output);
    assert!(stderr.contains("broken.ron:") && stderr.contains("\"mirror ball\".shape.radius"), "{stderr}");
    assert!(!out.exists());
}

#[test]
fn photon_statistics_are_printed() {
    let dir = temp_dir("photons");
    let run = |algo: &str, photons: &[&str]| {
        let output = gi_studio()
            .args(["render", "assets/scenes/caustics.ron", "--algo", algo])
            .args(["--spp", "3", "--width", "32", "--height", "24"])
            .args(photons)
            .arg("-o")
            .arg(dir.join(format!("{algo}.png")))
            .output()
            .unwrap();
        assert_exit(&output, 0);
        stdout(&output)
    };
    let photon = run("photon", &["--global-photons", "5000", "--caustic-photons", "5000"]);
    for map in ["global", "caustic"] {
        let line = photon.lines().find(|l| l.starts_with(&format!("{map} map:"))).expect(map);
        assert_eq!(number_before(line, "emitted"), 5000.0, "{line}");
        assert!(number_before(line, "stored") > 0.0 && line.contains("tree depth"), "{line}");
    }
    let knn = photon.lines().find(|l| l.starts_with("k-NN (last pass):")).expect("k-NN line");
    // At most one query of each map per camera sample (no final gather here)
    let queries = number_before(knn, "queries");
    assert!(queries > 0.0 && queries <= (2 * 32 * 24) as f64, "{knn}");
    assert!(number_before(knn, "nodes") > 0.0 && knn.contains("gather radius"), "{knn}");
    let sppm = run("sppm", &["--sppm-photons", "5000"]);
    assert!(sppm.contains("SPPM mean radius per pass [1: ") && sppm.contains("3: "), "{sppm}");
    assert_eq!(number_before(&sppm, "photons"), 5000.0, "{sppm}");
    // Every stage of the pass was clocked (each does work, so none is 0)
    let split = sppm.lines().find(|l| l.starts_with("SPPM last pass: ")).expect("the time split");
    for stage in ["eye pass", "photon tracing", "photon grid", "gather"] {
        let after = split.split(&format!("{stage} ")).nth(1).unwrap_or_else(|| panic!("no {stage} in {split}"));
        let ms: f64 = after.split_whitespace().next().and_then(|w| w.parse().ok()).expect("a number of ms");
        assert!(ms > 0.0 && after.split_whitespace().nth(1).is_some_and(|w| w.starts_with("ms")), "{split}");
    }
}

// ---- Nothing lost -----------------------------------------------------------

#[test]
fn reference_metadata_never_replaces_the_scene() {
    let dir = temp_dir("reference");
    let scene = cornell_copy(&dir, "my.ron");
    let original = std::fs::read(&scene).unwrap();
    let small = ["--spp", "1", "--width", "8", "--height", "6"];
    let output = gi_studio().arg("reference").arg(&scene).args(small).arg("-o").arg(dir.join("my.exr")).output();
    assert_exit(&output.unwrap(), 0);
    // --out-dir pointing at the scene's own folder writes my.exr beside my.ron
    let output = gi_studio().arg("reference").arg(&scene).args(small).arg("--out-dir").arg(&dir).output();
    assert_exit(&output.unwrap(), 0);
    assert_eq!(std::fs::read(&scene).unwrap(), original, "the scene was overwritten");
    assert_eq!(entries(&dir), ["my.exr", "my.exr.meta.ron", "my.ron"]);
    let info = gi_studio::analysis::reference::load_info(&dir.join("my.exr")).expect("metadata");
    assert_eq!((info.width, info.height, info.samples_per_pixel), (8, 6, 1));
}

#[test]
fn no_command_writes_over_its_input() {
    let dir = temp_dir("input");
    let scene = cornell_copy(&dir, "x.ron");
    let original = std::fs::read(&scene).unwrap();
    std::fs::hard_link(&scene, dir.join("x.png")).unwrap();
    for args in [
        vec!["photons", "x.ron", "-o", "x.ron", "--global-photons", "10", "--caustic-photons", "10"],
        vec!["photons", "x.ron", "-o", "./x.ron", "--force"],
        vec!["render", "x.ron", "-o", "x.png", "--force", "--spp", "1"],
    ] {
        let output = gi_studio().current_dir(&dir).args(&args).output().unwrap();
        assert_exit(&output, 1);
        assert!(stderr(&output).contains("is this command's input"), "{args:?}: {}", stderr(&output));
        assert_eq!(std::fs::read(&scene).unwrap(), original, "{args:?}");
    }
}

#[test]
fn a_file_the_program_did_not_write_is_replaced_only_with_force() {
    let dir = temp_dir("force");
    let photo = dir.join("holiday.png");
    std::fs::write(&photo, "someone's photo").unwrap();
    let render = |force: bool| {
        let mut command = gi_studio();
        command.args(["render", "assets/scenes/thesis.ron"]).args(SMALL).arg("-o").arg(&photo);
        if force {
            command.arg("--force");
        }
        command.output().unwrap()
    };
    let refused = render(false);
    assert_exit(&refused, 1);
    assert!(stderr(&refused).contains("was not written by GI Studio; pass --force"), "{}", stderr(&refused));
    assert_eq!(std::fs::read(&photo).unwrap(), b"someone's photo");
    assert_exit(&render(true), 0);
    assert_eq!(gi_studio::render::LinearImage::load(&photo).unwrap().width, 40);
}

/// A write that fails part way (here: the file-size limit, as a full disk
/// would) leaves the previous file whole and no partial file, and says why
/// once, with the path.
#[test]
fn a_failed_write_keeps_the_old_file_and_says_why_once() {
    let dir = temp_dir("full");
    let previous = dir.join("prev.exr");
    let scene = "assets/scenes/cornell.ron";
    let size = ["--spp", "1", "--width", "128", "--height", "96"];
    assert_exit(&gi_studio().args(["render", scene]).args(size).arg("-o").arg(&previous).output().unwrap(), 0);
    let before = std::fs::read(&previous).unwrap();
    // 16 blocks: far less than the image; SIGXFSZ ignored so the write fails
    let limited = || capped("trap '' XFSZ; ulimit -f 16 &&");
    let output = limited().args(["render", scene, "--seed", "3"]).args(size).arg("-o").arg(&previous).output();
    let output = output.unwrap();
    assert_exit(&output, 1);
    let message = stderr(&output);
    assert!(message.contains("prev.exr: File too large"), "{message}");
    assert_eq!(message.matches("File too large").count(), 1, "{message}");
    assert_eq!(std::fs::read(&previous).unwrap(), before);
    let photons = limited()
        .args(["photons", "assets/scenes/caustics.ron", "--global-photons", "20000", "-o"])
        .arg(dir.join("maps.pmap"))
        .output()
        .unwrap();
    assert_exit(&photons, 1);
    assert_eq!(entries(&dir), ["prev.exr"], "no partial file may be left");
}

#[test]
fn a_device_that_is_full_fails_the_render() {
    let dir = temp_dir("devfull");
    let link = dir.join("full.png");
    std::os::unix::fs::symlink("/dev/full", &link).unwrap();
    let output = gi_studio().args(["render", "assets/scenes/thesis.ron"]).args(SMALL).arg("-o").arg(&link).output();
    let output = output.unwrap();
    assert_exit(&output, 1);
    assert_eq!(stderr(&output).matches("No space left on device").count(), 1, "{}", stderr(&output));
    assert!(stdout(&output).is_empty(), "no summary for a failed write: {}", stdout(&output));
}

#[test]
fn a_missing_file_is_said_once() {
    let output = gi_studio().args(["render", "nowhere.ron", "-o", "x.png"]).output().unwrap();
    assert_exit(&output, 1);
    let message = stderr(&output);
    assert!(message.contains("nowhere.ron: No such file or directory"), "{message}");
    assert_eq!(message.matches("No such file").count(), 1, "{message}");
}

#[test]
fn a_bad_screenshot_path_is_refused_before_the_window_opens() {
    let dir = temp_dir("shot");
    for (path, says) in [(dir.join("x.jpg"), "PNG"), (dir.join("missing").join("x.png"), "does not exist")] {
        let output = gi_studio().arg("--screenshot").arg(&path).env_remove("DISPLAY").output().unwrap();
        assert_exit(&output, 1);
        assert!(stderr(&output).contains(says), "{}", stderr(&output));
    }
    assert!(entries(&dir).is_empty());
}

// ---- Nothing unbounded ----------------------------------------------------

/// Values no render can use are bad flags (exit 2), each naming the flag.
#[test]
fn values_out_of_their_limits_are_refused_by_name() {
    for (flag, value) in [
        ("--spp", "0"),
        ("--exposure", "NaN"),
        ("--exposure", "inf"),
        ("--exposure", "1e30"),
        ("--time", "NaN"),
        ("--time", "inf"),
        ("--time", "1e300"),
        ("--time", "-1"),
        ("--threads", "10000"),
        ("--k", "4294967295"),
        ("--width", "100000"),
        ("--height", "0"),
        ("--global-photons", "4294967295"),
        ("--sppm-photons", "0"),
        ("--sppm-alpha", "1.5"),
        ("--max-radius", "-1"),
        ("--clamp", "NaN"),
        ("--max-depth", "0"),
    ] {
        let output = gi_studio()
            .args(["render", "assets/scenes/cornell.ron", "-o", "never.png", &format!("{flag}={value}")])
            .output()
            .unwrap();
        assert_exit(&output, 2);
        let message = stderr(&output);
        assert!(message.contains(flag) && message.contains("must be"), "{flag} {value}: {message}");
    }
    let output = gi_studio().args(["bench", "--budget", "inf"]).output().unwrap();
    assert_exit(&output, 2);
    assert!(!Path::new("never.png").exists());
}

/// Each algorithm takes only its own knobs: another's is refused by name.
#[test]
fn a_knob_of_another_algorithm_is_refused() {
    let flags = [
        ("path", "--global-photons=10"),
        ("sppm", "--k=20"),
        ("photon", "--sppm-alpha=0.5"),
        ("bpm", "--merges=caustics"),
        ("bdpt", "--merges=everywhere"),
    ];
    for (algo, flag) in flags {
        let output = gi_studio()
            .args(["render", "assets/scenes/cornell.ron", "-o", "never.png", "--algo", algo, flag])
            .output()
            .unwrap();
        assert_exit(&output, 1);
        let name = flag.split('=').next().unwrap();
        assert!(stderr(&output).contains(&format!("{name} does not apply to --algo {algo}")), "{}", stderr(&output));
    }
}

#[test]
fn an_image_too_large_in_all_is_refused_before_rendering() {
    let output = gi_studio()
        .args(["render", "assets/scenes/cornell.ron", "-o", "never.png", "--width", "16384", "--height", "16384"])
        .output()
        .unwrap();
    assert_exit(&output, 1);
    assert!(stderr(&output).contains("at most 33554432 pixels"), "{}", stderr(&output));
}

#[test]
fn a_scene_that_is_not_a_regular_file_is_refused_at_once() {
    let dir = temp_dir("fifo");
    let fifo = dir.join("scene.ron");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    for scene in [fifo.as_path(), Path::new("/dev/zero")] {
        let child = gi_studio()
            .arg("render")
            .arg(scene)
            .arg("-o")
            .arg(dir.join("x.png"))
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Opening a FIFO would wait for a writer forever: guard the test
        // against hanging (a liveness check, not a speed threshold)
        let output = wait_or_kill(child, 60);
        assert_exit(&output, 1);
        assert!(stderr(&output).contains("not a regular file"), "{}", stderr(&output));
    }
}

fn wait_or_kill(mut child: std::process::Child, seconds: u64) -> Output {
    for _ in 0..seconds * 10 {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    child.kill().unwrap();
    panic!("the command did not return: it blocked");
}

#[test]
fn a_photon_map_claiming_billions_of_photons_is_refused_not_allocated() {
    let dir = temp_dir("pmap");
    let maps = dir.join("caustics.pmap");
    let make = gi_studio()
        .args(["photons", "assets/scenes/caustics.ron", "--global-photons", "500", "--caustic-photons", "500", "-o"])
        .arg(&maps)
        .output()
        .unwrap();
    assert_exit(&make, 0);
    let mut bytes = std::fs::read(&maps).unwrap();
    // The global map's photon count: after the 28-byte header and its emitted count
    bytes[36..44].copy_from_slice(&(1u64 << 34).to_le_bytes());
    std::fs::write(&maps, &bytes).unwrap();
    let output = gi_studio()
        .args(["render", "assets/scenes/caustics.ron", "--algo", "photon", "--global-photons", "500"])
        .args(["--caustic-photons", "500", "-o"])
        .arg(dir.join("x.png"))
        .arg("--photon-map")
        .arg(&maps)
        .output()
        .unwrap();
    assert_exit(&output, 1);
    assert!(stderr(&output).contains("claims 17179869184 photons"), "{}", stderr(&output));
}

// ---- References wherever the program runs -----------------------------------

/// The rows of a bench CSV: (scene, relMSE) of each.
fn relmse_rows(csv: &Path) -> Vec<(String, f64)> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("scene,algorithm,seconds,spp,rays,relmse,relmse_se,flip"));
    lines
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            (fields[0].to_owned(), fields[5].parse().unwrap_or_else(|_| panic!("a number in {line}")))
        })
        .collect()
}

/// The references kept in the cache under `cache` (XDG_CACHE_HOME).
fn cached(cache: &Path) -> Vec<String> {
    let dir = cache.join("gistudio").join("references");
    if !dir.exists() {
        return Vec::new();
    }
    entries(&dir).into_iter().filter(|name| name.ends_with(".exr")).collect()
}

#[test]
fn bench_finds_the_presets_references_from_any_folder() {
    let dir = temp_dir("bench-anywhere");
    let (cache, out) = (dir.join("cache"), dir.join("results"));
    // From the file system's root, with an empty cache and no reference
    // rendered (a budget of 0 refuses a scene without one)
    let output = gi_studio()
        .current_dir("/")
        .env("XDG_CACHE_HOME", &cache)
        .args(["bench", "--budget", "0.05", "--algos", "path", "--reference-budget", "0", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_exit(&output, 0);
    let rows = relmse_rows(&out.join("convergence.csv"));
    for preset in gi_studio::scene::presets::names() {
        let errors: Vec<f64> = rows.iter().filter(|(scene, _)| scene == preset).map(|(_, e)| *e).collect();
        assert!(!errors.is_empty(), "no rows for {preset}");
        assert!(errors.iter().all(|e| e.is_finite() && *e > 0.0), "{preset}: {errors:?}");
    }
    assert!(stdout(&output).contains("reference: path, 4096 spp"), "{}", stdout(&output));
    assert_eq!(cached(&cache), Vec::<String>::new(), "the built-in references need no cache");
}

/// FLIP in the bench's CSV, measured after the render (so as not to take
/// its CPU) but in the rows of the passes it measured: the first pass's,
/// then the first pass at 1.5 times the last one's time or later, and the
/// final image's; the early, noisier images further from the reference.
#[test]
fn bench_measures_flip_at_log_spaced_passes() {
    let dir = temp_dir("bench-flip");
    let out = dir.join("results");
    let output = gi_studio()
        .args(["bench", "--budget", "0.6", "--algos", "path", "--reference-budget", "0", "--out"])
        .arg(&out)
        .arg("assets/scenes/cornell.ron")
        .output()
        .unwrap();
    assert_exit(&output, 0);
    let text = std::fs::read_to_string(out.join("convergence.csv")).unwrap();
    // (seconds, FLIP if measured) of each pass
    let rows: Vec<(f64, Option<f64>)> = text
        .lines()
        .skip(1)
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            (fields[2].parse().unwrap(), fields[7].parse().ok())
        })
        .collect();
    assert!(rows.len() >= 8, "enough passes to space ({} rows)", rows.len());
    let mut next = 0.0;
    for (i, &(seconds, flip)) in rows.iter().enumerate() {
        let due = seconds >= next || i == rows.len() - 1;
        assert_eq!(flip.is_some(), due, "pass {i} at {seconds} s (FLIP due from {next} s)");
        if seconds >= next {
            next = seconds * 1.5;
        }
        if let Some(flip) = flip {
            assert!(flip > 0.0 && flip < 1.0, "pass {i}: FLIP {flip}");
        }
    }
    let (first, last) = (rows[0].1.unwrap(), rows[rows.len() - 1].1.unwrap());
    assert!(first > last * 1.2, "one pass's FLIP {first}, the last's {last}");
}

#[test]
fn an_edited_scene_gets_its_own_reference_and_bench_measures_against_it_from_elsewhere() {
    let dir = temp_dir("edited-reference");
    let elsewhere = temp_dir("edited-reference-elsewhere");
    let cache = dir.join("cache");
    let preset = include_str!("../assets/scenes/cornell.ron");
    let edited = preset.replace("width: 640, height: 480", "width: 64, height: 48");
    assert_ne!(edited, preset);
    let scene = dir.join("edited.ron");
    std::fs::write(&scene, &edited).unwrap();
    let bench = |scene: &Path, out: &str| {
        let mut command = gi_studio();
        command.current_dir(&elsewhere).env("XDG_CACHE_HOME", &cache);
        command.args(["bench", "--budget", "0.05", "--algos", "path", "--reference-budget", "0", "--out", out]);
        command.arg(scene).output().unwrap()
    };
    let reference = |scene: &Path| {
        let mut command = gi_studio();
        command.current_dir(&elsewhere).env("XDG_CACHE_HOME", &cache);
        command.args(["reference", "--spp", "64"]).arg(scene).output().unwrap()
    };
    // No reference yet: one sentence naming the command that makes it
    let refused = bench(&scene, "first");
    assert_exit(&refused, 1);
    let message = stderr(&refused);
    assert!(message.contains("no reference for") && message.contains("gi-studio reference"), "{message}");
    assert_eq!(message.trim().lines().count(), 1, "{message}");
    // Made once, into the cache; bench from another folder then measures
    let made = reference(&scene);
    assert_exit(&made, 0);
    assert!(stdout(&made).contains("path tracing"), "the method is named: {}", stdout(&made));
    assert_eq!(cached(&cache).len(), 1);
    let measured = bench(&scene, "second");
    assert_exit(&measured, 0);
    let rows = relmse_rows(&elsewhere.join("second").join("convergence.csv"));
    assert!(!rows.is_empty() && rows.iter().all(|(name, e)| name == "edited" && e.is_finite()), "{rows:?}");
    // A further edit is another scene: refused again, and its reference is
    // a second entry beside the first
    let further = dir.join("further.ron");
    std::fs::write(&further, edited.replace("fov_y_degrees: 40.0", "fov_y_degrees: 41.0")).unwrap();
    assert_exit(&bench(&further, "third"), 1);
    assert_exit(&reference(&further), 0);
    assert_eq!(cached(&cache).len(), 2);
    assert_exit(&bench(&further, "fourth"), 0);
}

/// `--help` names every algorithm the binary renders.
#[test]
fn help_names_every_algorithm() {
    let output = gi_studio().arg("--help").output().unwrap();
    assert_exit(&output, 0);
    let help = stdout(&output).to_lowercase().replace('\n', " ");
    let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
    for algorithm in gi_studio::render::Algorithm::ALL {
        assert!(help.contains(&algorithm.label().to_lowercase()), "--help does not name {}", algorithm.label());
    }
}

/// A point light inside the glass ball: path tracing and Whitted say, in
/// one line, that they cannot see it and which algorithms can; VCM renders
/// it without a word.
#[test]
fn a_light_inside_glass_is_named_by_the_algorithms_that_cannot_see_it() {
    let dir = temp_dir("bulb");
    let scene = dir.join("bulb.ron");
    let bulb =
        "lights: [(name: \"bulb\", kind: Point(position: (0.45, 0.35, 0.2)), color: (1.0, 1.0, 1.0), intensity: 5.0)],";
    let text = std::fs::read_to_string("assets/scenes/cornell.ron").unwrap().replace("lights: [],", bulb);
    std::fs::write(&scene, text).unwrap();
    for (algo, warned) in [("path", true), ("whitted", true), ("vcm", false)] {
        let output = gi_studio()
            .arg("render")
            .arg(&scene)
            .args(["--algo", algo])
            .args(SMALL)
            .arg("-o")
            .arg(dir.join(format!("{algo}.png")))
            .output()
            .unwrap();
        assert_exit(&output, 0);
        let warnings: Vec<String> =
            stderr(&output).lines().filter(|l| l.starts_with("warning:")).map(str::to_owned).collect();
        if warned {
            assert_eq!(warnings.len(), 1, "{warnings:?}");
            assert!(warnings[0].contains("light “bulb” is inside the glass of “glass ball”"), "{}", warnings[0]);
            assert!(warnings[0].contains("Vertex connection and merging"), "{}", warnings[0]);
        } else {
            assert!(warnings.is_empty(), "{algo}: {warnings:?}");
        }
    }
}
