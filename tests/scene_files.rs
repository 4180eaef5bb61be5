//! Scene files: round trips, and one test per validation mistake, each
//! checking the problem, the field and the line it is reported on.

use std::path::Path;

use gi_studio::scene::{parse_scene, presets, to_ron, Problem, SceneFileError};

const CORNELL: &str = include_str!("../assets/scenes/cornell.ron");
const LIGHTS: &str = include_str!("../assets/scenes/lights.ron");

/// Replace `from` (which must occur once) and parse.
fn broken(text: &str, from: &str, to: &str) -> SceneFileError {
    assert_eq!(text.matches(from).count(), 1, "`{from}` must occur once");
    parse_scene(&text.replacen(from, to, 1), Path::new("broken.ron")).expect_err("must be refused")
}

/// The line (1-based) of the first occurrence of `needle` after the edit.
fn line_of(text: &str, needle: &str) -> usize {
    text[..text.find(needle).expect("needle")].matches('\n').count() + 1
}

fn assert_invalid(error: SceneFileError, field: &str, line: usize, check: impl Fn(&Problem) -> bool) {
    let message = error.to_string();
    match error {
        SceneFileError::Invalid { invalid, line: found, column, path, .. } => {
            assert!(check(&invalid.problem), "wrong problem: {message}");
            assert_eq!(invalid.field, field, "{message}");
            assert_eq!(found, line, "{message}");
            assert!(column >= 1);
            assert_eq!(path, Path::new("broken.ron"));
            assert!(message.starts_with(&format!("broken.ron:{line}:")), "{message}");
        }
        other => panic!("expected a validation error, got {other}"),
    }
}

#[test]
fn every_preset_round_trips() {
    for name in presets::names() {
        let scene = presets::preset(name).unwrap().unwrap();
        let text = to_ron(&scene).unwrap();
        let again = parse_scene(&text, Path::new("again.ron")).unwrap();
        assert_eq!(scene, again, "{name}");
        assert_eq!(scene.content_key(), again.content_key());
    }
}

#[test]
fn negative_radius() {
    let e = broken(CORNELL, "radius: 0.35), material: \"mirror\"", "radius: -0.35), material: \"mirror\"");
    assert_invalid(
        e,
        "objects[5] \"mirror ball\".shape.radius",
        line_of(CORNELL, "\"mirror ball\""),
        |p| matches!(p, Problem::NotPositive(r) if *r == -0.35),
    );
}

#[test]
fn zero_radius() {
    let e = broken(CORNELL, "radius: 0.35), material: \"glass\"", "radius: 0.0), material: \"glass\"");
    assert_invalid(e, "objects[6] \"glass ball\".shape.radius", line_of(CORNELL, "\"glass ball\", shape"), |p| {
        matches!(p, Problem::NotPositive(_))
    });
}

#[test]
fn not_a_number() {
    let e = broken(CORNELL, "fov_y_degrees: 40.0", "fov_y_degrees: NaN");
    assert_invalid(
        e,
        "camera.fov_y_degrees",
        line_of(CORNELL, "fov_y_degrees"),
        |p| matches!(p, Problem::NotFinite(v) if v.is_nan()),
    );
}

#[test]
fn infinity() {
    let e = broken(CORNELL, "radiance: (15.0, 15.0, 15.0)", "radiance: (15.0, inf, 15.0)");
    assert_invalid(
        e,
        "materials[5] \"panel\".model.radiance",
        line_of(CORNELL, "radiance"),
        |p| matches!(p, Problem::NotFinite(v) if v.is_infinite()),
    );
}

#[test]
fn cone_angle_zero_and_above_ninety() {
    for angle in ["0.0", "95.0"] {
        let e = broken(LIGHTS, "cone_angle_degrees: 25.0", &format!("cone_angle_degrees: {angle}"));
        assert_invalid(e, "lights[1] \"spot\".kind.cone_angle_degrees", line_of(LIGHTS, "cone_angle_degrees"), |p| {
            matches!(p, Problem::ConeAngle(_))
        });
    }
}

#[test]
fn zero_length_direction() {
    let e = broken(LIGHTS, "Directional(direction: (-1.0, -1.0, -0.6))", "Directional(direction: (0.0, 0.0, 0.0))");
    assert_invalid(e, "lights[2] \"sun\".kind.direction", line_of(LIGHTS, "\"sun\""), |p| *p == Problem::ZeroLength);
}

#[test]
fn zero_length_up() {
    let e = broken(CORNELL, "up: (0.0, 1.0, 0.0)", "up: (0.0, 0.0, 0.0)");
    assert_invalid(e, "camera.up", line_of(CORNELL, "up:"), |p| *p == Problem::ZeroLength);
}

#[test]
fn up_parallel_to_view() {
    let e = broken(CORNELL, "up: (0.0, 1.0, 0.0)", "up: (0.0, 0.0, -2.0)");
    assert_invalid(e, "camera.up", line_of(CORNELL, "up:"), |p| *p == Problem::UpParallelToView);
}

#[test]
fn attenuation_all_zero() {
    let text = LIGHTS.replacen("intensity: 12.0)", "intensity: 12.0, attenuation: (a: 0.0, b: 0.0, c: 0.0))", 1);
    let e = broken(&text, "attenuation: (a: 0.0", "attenuation: (a: 0.0");
    assert_invalid(e, "lights[0] \"point\".attenuation.a", line_of(&text, "attenuation"), |p| {
        *p == Problem::ZeroAttenuation
    });
}

#[test]
fn index_of_refraction_not_positive() {
    for ior in ["0.0", "-1.5"] {
        let e = broken(CORNELL, "ior: 1.5", &format!("ior: {ior}"));
        assert_invalid(e, "materials[4] \"glass\".model.ior", line_of(CORNELL, "ior:"), |p| {
            matches!(p, Problem::NotPositive(_))
        });
    }
}

#[test]
fn unknown_material() {
    let e = broken(CORNELL, "material: \"green\")", "material: \"teal\")");
    assert_invalid(e, "objects[4] \"right wall\".material", line_of(CORNELL, "\"right wall\""), |p| {
        *p == Problem::UnknownMaterial("teal".into())
    });
}

#[test]
fn duplicate_names() {
    let e = broken(CORNELL, "(name: \"glass ball\"", "(name: \"mirror ball\"");
    let text = CORNELL.replacen("(name: \"glass ball\"", "(name: \"mirror ball\"", 1);
    assert_invalid(e, "objects[6] \"mirror ball\".name", line_of(&text, "\"right wall\"") + 2, |p| {
        *p == Problem::DuplicateName("mirror ball".into())
    });
}

#[test]
fn syntax_and_unknown_field_errors_have_positions() {
    let e = broken(CORNELL, "fov_y_degrees: 40.0", "fov_y_degrees 40.0");
    assert!(matches!(e, SceneFileError::Syntax { line, .. } if line == line_of(CORNELL, "fov_y_degrees")), "{e}");
    let e = broken(CORNELL, "fov_y_degrees: 40.0", "fov_degrees: 40.0");
    let message = e.to_string();
    assert!(matches!(e, SceneFileError::Syntax { .. }) && message.contains("fov_degrees"), "{message}");
}

/// A typo inside a shape, a material or a light is an error naming the
/// field and its line, not a default silently rendered.
#[test]
fn unknown_fields_inside_shapes_materials_and_lights_are_refused() {
    for (text, from, to, field) in [
        (CORNELL, "radius: 0.35), material: \"mirror\"", "radus: 0.35), material: \"mirror\"", "radus"),
        (CORNELL, "ior: 1.5", "ior: 1.5, tnit: (1.0, 1.0, 1.0)", "tnit"),
        (LIGHTS, "cone_angle_degrees: 25.0", "cone_angle_degrees: 25.0, falof: 2.0", "falof"),
        (LIGHTS, "intensity: 12.0)", "intensity: 12.0, attenuation: (a: 1.0, d: 2.0))", "d"),
    ] {
        let e = broken(text, from, to);
        let message = e.to_string();
        let edited = text.replacen(from, to, 1);
        match e {
            SceneFileError::Syntax { line, .. } => assert_eq!(line, line_of(&edited, to), "{message}"),
            other => panic!("expected a syntax error for {field}, got {other}"),
        }
        assert!(message.contains(&format!("`{field}`")), "{message}");
    }
}

#[test]
fn exposure_and_size_beyond_their_limits_are_refused() {
    let e = broken(CORNELL, "exposure: 0.0", "exposure: 1e30");
    assert_invalid(e, "settings.exposure", line_of(CORNELL, "exposure"), |p| matches!(p, Problem::OutOfRange { .. }));
    let e = broken(CORNELL, "width: 640, height: 480", "width: 16384, height: 16384");
    assert_invalid(e, "settings.height", line_of(CORNELL, "width: 640"), |p| {
        matches!(p, Problem::TooManyPixels { width: 16384, height: 16384 })
    });
}

/// The saved (pretty, one field a line) form of a scene: a duplicate name
/// is reported on the second name's line, a missing material on the
/// `material:` line of its object, whichever order the object's fields
/// are written in.
#[test]
fn problems_in_the_saved_form_are_on_their_own_lines() {
    let scene = presets::preset("cornell").unwrap().unwrap();
    let saved = to_ron(&scene).unwrap();
    let at = |text: &str, line: usize| text.lines().nth(line - 1).unwrap_or_default().to_owned();
    let line_of_error = |text: &str| match parse_scene(text, Path::new("broken.ron")) {
        Err(SceneFileError::Invalid { line, .. }) => line,
        other => panic!("expected a validation error, got {other:?}"),
    };

    // The second of two objects named "floor"
    let twice = saved.replacen("name: \"ceiling\"", "name: \"floor\"", 1);
    let line = line_of_error(&twice);
    assert_eq!(line, line_of(&saved, "name: \"ceiling\""), "line {line}: {}", at(&twice, line));

    // A missing material, and the same with `material:` before `name:`
    let missing = saved.replacen("material: \"red\"", "material: \"nowhere\"", 1);
    let line = line_of_error(&missing);
    assert!(at(&missing, line).contains("\"nowhere\""), "line {line}: {}", at(&missing, line));
    let reordered = CORNELL.replacen(
        "(name: \"left wall\", shape: Plane(point: (-1.0, 0.0, 0.0), normal: (1.0, 0.0, 0.0)), material: \"red\")",
        "(material: \"nowhere\",\n         name: \"left wall\", shape: Plane(point: (-1.0, 0.0, 0.0), normal: (1.0, 0.0, 0.0)))",
        1,
    );
    let line = line_of_error(&reordered);
    assert!(at(&reordered, line).contains("\"nowhere\""), "line {line}: {}", at(&reordered, line));

    // An object named as a material, whose name the objects' section first
    // shows as an earlier object's material
    let named_white = CORNELL.replacen("(name: \"ceiling\"", "(name: \"white\"", 1).replacen(
        "material: \"glass\")",
        "material: \"nowhere\")",
        1,
    );
    let line = line_of_error(&named_white);
    assert!(at(&named_white, line).contains("\"nowhere\""), "line {line}: {}", at(&named_white, line));
}

/// A name of 10,000 characters is not echoed in full: the message names
/// it by its first 40.
#[test]
fn a_huge_name_is_cut_in_the_message() {
    let long = "x".repeat(10_000);
    let twice = CORNELL.replacen("name: \"floor\"", &format!("name: \"{long}\""), 1).replacen(
        "name: \"ceiling\"",
        &format!("name: \"{long}\""),
        1,
    );
    let missing = CORNELL.replacen("material: \"red\")", &format!("material: \"{long}\")"), 1);
    for text in [twice, missing] {
        let message = parse_scene(&text, Path::new("broken.ron")).unwrap_err().to_string();
        assert!(message.len() < 300, "{} characters: {}…", message.len(), &message[..200]);
        assert!(message.contains(&format!("{}…", "x".repeat(40))), "{message}");
    }
}
