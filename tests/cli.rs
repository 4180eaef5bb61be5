//! The headless binary as a user runs it.

use std::process::Command;

fn gi_studio() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gi-studio"))
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("gi-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn render_writes_png_and_exr_and_prints_a_summary() {
    let dir = temp_dir("ok");
    for (algo, file) in [("path", "a.png"), ("whitted", "b.exr")] {
        let out = dir.join(file);
        let output = gi_studio()
            .args([
                "render",
                "assets/scenes/cornell.ron",
                "--algo",
                algo,
                "--spp",
                "2",
                "--width",
                "40",
                "--height",
                "30",
                "-o",
            ])
            .arg(&out)
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        let summary = String::from_utf8_lossy(&output.stdout);
        assert!(summary.contains("40×30") && summary.contains(algo) && summary.contains("2 spp"), "{summary}");
        assert!(
            summary.contains("samples/s") && summary.contains("rays/s") && summary.contains("0 non-finite"),
            "{summary}"
        );
        let image = gi_studio::render::LinearImage::load(&out).unwrap();
        assert_eq!((image.width, image.height), (40, 30));
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
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("broken.ron:"), "{stderr}");
    assert!(stderr.contains("\"mirror ball\".shape.radius"), "{stderr}");
    assert!(!out.exists());
}

#[test]
fn photon_statistics_are_printed() {
    let dir = temp_dir("photons");
    let run = |algo: &str| {
        let output = gi_studio()
            .args([
                "render",
                "assets/scenes/caustics.ron",
                "--algo",
                algo,
                "--spp",
                "3",
                "--width",
                "32",
                "--height",
                "24",
            ])
            .args(["--global-photons", "5000", "--caustic-photons", "5000", "--sppm-photons", "5000", "-o"])
            .arg(dir.join(format!("{algo}.png")))
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        String::from_utf8_lossy(&output.stdout).into_owned()
    };
    let photon = run("photon");
    for needle in [
        "global map: 5000 emitted",
        "caustic map: 5000 emitted",
        "tree depth",
        "k-NN (last pass):",
        "nodes visited",
        "µs per query",
        "gather radius",
    ] {
        assert!(photon.contains(needle), "missing {needle:?} in:\n{photon}");
    }
    let sppm = run("sppm");
    assert!(sppm.contains("SPPM mean radius per pass [1: ") && sppm.contains("3: "), "{sppm}");
    assert!(sppm.contains("traced 5000 photons"), "{sppm}");
}
