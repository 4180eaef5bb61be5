//! The studio driven as a user drives it (egui_kittest, no window).

use std::path::PathBuf;

use eframe::egui;
use eframe::Storage as _;
use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use gi_studio::app::{Against, Selection, StudioApp};
use gi_studio::app::{StateFile, StudioArgs};
use gi_studio::render::world::camera::CameraModel;
use gi_studio::render::Algorithm;
use gi_studio::scene::Shape;

/// The studio's arguments in tests: references kept under the target
/// folder, never in the user's cache.
fn test_args() -> StudioArgs {
    let cache = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("studio-ui-references");
    StudioArgs { reference_cache: Some(cache), ..Default::default() }
}

fn studio(panes: usize) -> Harness<'static, StudioApp> {
    let args = StudioArgs { panes: Some(panes), ..test_args() };
    let mut app = StudioApp::new(&egui::Context::default(), None, &args);
    // Small images keep the tests quick
    for pane in app.panes_mut().list_mut() {
        pane.settings_mut().width = 64;
        pane.settings_mut().height = 48;
        pane.settings_mut().samples_per_pixel = Some(2);
        pane.settings_mut().set_photons(5_000);
    }
    app.restart_all();
    Harness::builder().with_size([1400.0, 900.0]).build_ui_state(|ui, app: &mut StudioApp| app.show(ui), app)
}

/// Step until `done` holds (tiles arrive from the worker over several frames).
fn step_until(harness: &mut Harness<'static, StudioApp>, done: impl Fn(&StudioApp) -> bool) {
    step_frames_until(harness, 3000, done);
}

/// Step at most `frames` frames, 2 ms apart, until `done` holds.
fn step_frames_until(harness: &mut Harness<'static, StudioApp>, frames: usize, done: impl Fn(&StudioApp) -> bool) {
    for _ in 0..frames {
        harness.step();
        if done(harness.state()) {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    panic!("condition not reached");
}

/// A mouse drag from `start` by `by`, in `steps` moves a frame apart, as a
/// hand makes it (press, moves, release).
fn drag(harness: &mut Harness<'static, StudioApp>, start: egui::Pos2, by: egui::Vec2, steps: u32) {
    harness.hover_at(start);
    harness.run_steps(1);
    harness.drag_at(start);
    harness.run_steps(1);
    for step in 1..=steps {
        harness.hover_at(start + by * (step as f32 / steps as f32));
        harness.run_steps(1);
    }
    harness.drop_at(start + by);
    harness.run_steps(2);
}

fn radius_of(app: &StudioApp, name: &str) -> f32 {
    match app.scene().objects.iter().find(|o| o.name == name).map(|o| &o.shape) {
        Some(Shape::Sphere { radius, .. }) => *radius,
        _ => panic!("no sphere {name}"),
    }
}

#[test]
fn editing_a_radius_in_the_inspector_restarts_and_undo_redo_restore_both_states() {
    let mut harness = studio(1);
    step_until(&mut harness, |app| app.panes().list()[0].state().passes() >= 1);
    let original = harness.state().scene().clone();
    let generation = harness.state().panes().generations()[0];
    harness.get_by_label("mirror ball (sphere)").click();
    harness.run_steps(2);
    assert_eq!(harness.state().selection(), Selection::Object(5));
    let radius = harness.get_by_role_and_label(Role::SpinButton, "Radius");
    radius.click();
    harness.run_steps(2);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_role_and_label(Role::SpinButton, "Radius").type_text("0.2");
    harness.key_press(egui::Key::Enter);
    harness.run_steps(3);
    assert_eq!(radius_of(harness.state(), "mirror ball"), 0.2);
    assert!(harness.state().panes().generations()[0] > generation, "the edit must restart the render");
    let edited = harness.state().scene().clone();

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(*harness.state().scene(), original);
    harness.key_press_modifiers(egui::Modifiers::COMMAND | egui::Modifiers::SHIFT, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(*harness.state().scene(), edited);
}

/// Typing `0.45` into a radius is one edit when it is committed: the
/// half-typed 0, 0. and 0.4 neither change the scene nor restart the panes,
/// and one undo goes back to the radius before.
#[test]
fn a_typed_value_is_one_edit_when_committed() {
    let mut harness = studio(1);
    step_until(&mut harness, |app| app.panes().list()[0].state().passes() >= 1);
    let original = harness.state().scene().clone();
    harness.get_by_label("glass ball (sphere)").click();
    harness.run_steps(2);
    harness.get_by_role_and_label(Role::SpinButton, "Radius").click();
    harness.run_steps(2);
    let generation = harness.state().panes().generations()[0];
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    for key in ["0", ".", "4", "5"] {
        harness.get_by_role_and_label(Role::SpinButton, "Radius").type_text(key);
        harness.run_steps(2);
        assert_eq!(*harness.state().scene(), original, "typing {key} changed the scene before Enter");
        assert_eq!(harness.state().panes().generations()[0], generation, "typing {key} restarted the pane");
    }
    harness.key_press(egui::Key::Enter);
    harness.run_steps(3);
    assert_eq!(radius_of(harness.state(), "glass ball"), 0.45);
    assert_eq!(harness.state().panes().generations()[0], generation + 1, "one restart for the one edit");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(*harness.state().scene(), original, "one undo step");
}

/// Three wheel notches over a pane dolly the camera over many frames, each
/// rendered; the gesture is one undo step.
#[test]
fn a_dolly_gesture_is_one_undo_step() {
    let mut harness = studio(1);
    harness.run_steps(2);
    let original = harness.state().scene().clone();
    let centre = harness.state().panes().rects()[0].center();
    harness.hover_at(centre);
    harness.run_steps(1);
    for _ in 0..3 {
        harness.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Line,
            delta: egui::vec2(0.0, 1.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Wheel,
            modifiers: egui::Modifiers::NONE,
        });
        harness.run_steps(1);
    }
    // The smooth scroll goes on for a while after the last notch
    harness.run_steps(8);
    let dollied = harness.state().scene().camera.position;
    assert!(dollied.distance(original.camera.position) > 0.1, "the wheel did not dolly: {dollied}");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(*harness.state().scene(), original, "one undo takes back the whole gesture");
}

/// A point light inside the glass ball: each pane whose algorithm cannot
/// see it says so on its image.
#[test]
fn panes_say_when_their_algorithm_cannot_see_a_light() {
    let mut harness = studio(2);
    harness.run_steps(2);
    assert!(harness.query_by_label_contains("cannot see its light").is_none());
    harness.state_mut().edit_scene(|scene| {
        scene.lights.push(gi_studio::scene::Light {
            name: "bulb".into(),
            kind: gi_studio::scene::LightKind::Point { position: glam::Vec3::new(0.45, 0.35, 0.2) },
            color: glam::Vec3::ONE,
            intensity: 5.0,
            attenuation: gi_studio::scene::Attenuation::default(),
            enabled: true,
        })
    });
    harness.run_steps(3);
    harness.get_by_label_contains("Path tracing cannot see its light");
    harness.get_by_label_contains("Whitted ray tracing cannot see its light");
}

#[test]
fn toggling_a_light_changes_the_scene_and_restarts() {
    let mut harness = studio(1);
    harness.state_mut().open_path(&PathBuf::from("assets/scenes/thesis.ron"));
    harness.state_mut().panes_mut().list_mut()[0].settings_mut().width = 64;
    harness.state_mut().panes_mut().list_mut()[0].settings_mut().height = 48;
    harness.state_mut().restart_all();
    harness.run_steps(2);
    let generation = harness.state().panes().generations()[0];
    assert!(harness.state().scene().lights[0].enabled);
    harness.get_all_by_role(Role::CheckBox).next().expect("a light checkbox").click();
    harness.run_steps(2);
    assert!(!harness.state().scene().lights[0].enabled);
    assert!(harness.state().panes().generations()[0] > generation);
}

#[test]
fn a_broken_file_shows_its_error_and_leaves_the_scene_unchanged() {
    let mut harness = studio(1);
    harness.run_steps(2);
    let before = harness.state().scene().clone();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("gi-ui-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("broken.ron");
    std::fs::write(&path, include_str!("../assets/scenes/cornell.ron").replacen("ior: 1.5", "ior: -2.0", 1)).unwrap();
    harness.state_mut().open_path(&path);
    harness.run_steps(2);
    assert_eq!(*harness.state().scene(), before);
    let error = harness.state().messages().error.clone().expect("an error is shown");
    assert!(error.contains("broken.ron:") && error.contains("ior"), "{error}");
    harness.get_by_label_contains("broken.ron:");
}

#[test]
fn four_panes_show_four_algorithms() {
    let mut harness = studio(1);
    harness.run_steps(2);
    harness.get_by_label("View").click();
    harness.run_steps(2);
    harness.get_by_label("4 panes").click();
    harness.run_steps(3);
    let app = harness.state();
    assert_eq!(app.panes().count(), 4);
    let algorithms: Vec<_> = app.panes().list().iter().map(|p| p.algorithm()).collect();
    assert_eq!(algorithms[0], Algorithm::Path, "the pane there was keeps its algorithm");
    let mut sorted = algorithms.clone();
    sorted.sort_by_key(|a| a.name());
    let mut four = gi_studio::app::FOUR_PANES.to_vec();
    four.sort_by_key(|a| a.name());
    assert_eq!(sorted, four, "four different algorithms: {algorithms:?}");
    for pane in 1..=4 {
        harness.get_by_label(&format!("pane {pane}"));
    }
}

/// Going from four panes to two keeps the first two panes as they were:
/// a BDPT and a VCM pane with their settings stay BDPT and VCM.
#[test]
fn fewer_panes_keep_their_algorithms_and_settings() {
    let mut harness = studio(4);
    for (pane, algorithm) in
        harness.state_mut().panes_mut().list_mut().iter_mut().zip([Algorithm::Bdpt, Algorithm::Vcm])
    {
        pane.settings_mut().method = gi_studio::render::Method::of(algorithm);
        pane.settings_mut().max_depth = 7;
    }
    harness.state_mut().restart_all();
    harness.run_steps(2);
    let before: Vec<_> = harness.state().panes().list()[..2].iter().map(|p| p.settings().clone()).collect();
    harness.get_by_label("View").click();
    harness.run_steps(2);
    harness.get_by_label("2 panes").click();
    harness.run_steps(3);
    let after = harness.state().panes().list();
    assert_eq!(after.len(), 2);
    for (was, pane) in before.iter().zip(after) {
        assert_eq!(pane.algorithm(), was.algorithm());
        assert_eq!(pane.settings().method, was.method);
        assert_eq!(pane.settings().max_depth, 7);
    }
}

/// The panes stay where they are while the plots fill with statistics (a
/// click meant for a pane's menu must not land on the image below it),
/// and each pane's header stays within its own column, however many
/// buttons it has.
#[test]
fn panes_stay_put_and_headers_stay_in_their_columns() {
    let mut harness = studio(4);
    for (pane, algorithm) in
        harness.state_mut().panes_mut().list_mut().iter_mut().zip([Algorithm::Bdpt, Algorithm::Vcm])
    {
        pane.settings_mut().method = gi_studio::render::Method::of(algorithm);
    }
    harness.state_mut().restart_all();
    harness.set_size(egui::vec2(1000.0, 800.0));
    harness.run_steps(3);
    let before = harness.state().panes().rects().to_vec();
    step_until(&mut harness, |app| {
        app.panes().list().iter().all(|p| p.state().passes() >= 2) && app.panes().list()[2].state().maps.is_some()
    });
    harness.run_steps(3);
    assert_eq!(harness.state().panes().rects(), before.as_slice(), "the panes moved as the plots filled");
    let area = harness.state().panes().area();
    let column_width = area.width() / 2.0;
    for (column, button) in harness.get_all_by_label("Strategies").enumerate() {
        let left = area.min.x + column as f32 * column_width;
        let rect = button.rect();
        assert!(
            rect.min.x >= left && rect.max.x <= left + column_width,
            "pane {}'s Strategies button at {rect:?} is outside its column from {left} to {}",
            column + 1,
            left + column_width
        );
    }
}

#[test]
fn exporting_a_pane_writes_a_png_of_the_panes_size() {
    let mut harness = studio(1);
    step_until(&mut harness, |app| app.panes().list()[0].state().passes() >= 1);
    let path =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("gi-ui-export-{}.png", std::process::id()));
    harness.state_mut().export_pane(0, &path);
    let decoded = image::open(&path).expect("a PNG").to_rgb8();
    assert_eq!((decoded.width(), decoded.height()), (64, 48));
    // The pane's image as shown: each pixel tone-mapped at the pane's exposure
    let pane = &harness.state().panes().list()[0];
    for (i, (png, linear)) in decoded.pixels().zip(&pane.state().image.pixels).enumerate() {
        assert_eq!(png.0, gi_studio::render::image::tonemap_srgb8(*linear, pane.exposure()), "pixel {i}");
    }
    assert!(decoded.pixels().any(|p| p.0 != [0, 0, 0]), "a rendered image, not a black one");
}

/// Type `path` into the open file dialog's path field and press its `verb`.
fn answer_file_dialog(harness: &mut Harness<'static, StudioApp>, path: &std::path::Path, verb: &str) {
    let field = harness.get_by_role(Role::TextInput);
    field.focus();
    harness.run_steps(1);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_role(Role::TextInput).type_text(&path.display().to_string());
    harness.run_steps(1);
    harness.get_by_label(verb).click();
    harness.run_steps(3);
}

/// File ▸ Export image lists each pane with its algorithm; the dialog
/// names the pane, and the file holds that pane's image.
#[test]
fn exporting_from_the_menu_writes_the_chosen_pane() {
    let mut harness = studio(2);
    // Finished: the image compared below is the one exported
    step_until(&mut harness, |app| app.panes().list().iter().all(|p| p.state().finished));
    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label("Export image").click();
    harness.run_steps(2);
    harness.get_by_label("Pane 2: Whitted ray tracing");
    harness.get_all_by_label("PNG (display)…").nth(1).expect("pane 2's PNG").click();
    harness.run_steps(4);
    harness.get_by_label("Export pane 2's image (Whitted ray tracing) as PNG");
    let path =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("gi-ui-pane2-{}.png", std::process::id()));
    answer_file_dialog(&mut harness, &path, "Save");
    let decoded = image::open(&path).expect("a PNG").to_rgb8();
    let pane = &harness.state().panes().list()[1];
    for (png, linear) in decoded.pixels().zip(&pane.state().image.pixels) {
        assert_eq!(png.0, gi_studio::render::image::tonemap_srgb8(*linear, pane.exposure()));
    }
}

/// Save as… suggests the working folder (not the source tree's
/// assets/scenes); a failed save's error goes once a save succeeds, which
/// says "Saved".
#[test]
fn save_suggests_the_working_folder_and_a_good_save_clears_a_failed_ones_error() {
    let mut harness = studio(1);
    harness.run_steps(2);
    let open_save_as = |harness: &mut Harness<'static, StudioApp>| {
        harness.get_by_label("File").click();
        harness.run_steps(2);
        harness.get_by_label("Save as…").click();
        // The command applies after the frame; a window's first frame sizes it
        harness.run_steps(4);
    };
    open_save_as(&mut harness);
    let suggested = harness.get_by_role(Role::TextInput).value().unwrap_or_default();
    let here = std::env::current_dir().unwrap().join("untitled.ron");
    assert_eq!(suggested, here.display().to_string());
    let folder = tempfile::tempdir().unwrap();
    answer_file_dialog(&mut harness, &folder.path().join("no such folder").join("a.ron"), "Save");
    assert!(harness.state().messages().error.is_some(), "a save into a missing folder fails");
    open_save_as(&mut harness);
    let good = folder.path().join("b.ron");
    answer_file_dialog(&mut harness, &good, "Save");
    assert!(good.exists());
    assert_eq!(harness.state().messages().error, None, "the failed save's error stayed");
    assert!(harness.state().messages().status.starts_with("Saved"), "{}", harness.state().messages().status);
}

/// A sphere added from the inspector is seen: the centre of the view
/// meets it (it was added inside the middle ball, out of sight).
#[test]
fn a_new_sphere_is_placed_where_the_camera_looks() {
    use gi_studio::render::world::World;
    let mut harness = studio(1);
    harness.run_steps(2);
    harness.get_all_by_label("Add").next().expect("the objects' Add").click();
    harness.run_steps(2);
    harness.get_by_label("Sphere").click();
    harness.run_steps(2);
    let scene = harness.state().scene().clone();
    let added = scene.objects.len() - 1;
    assert_eq!(harness.state().selection(), Selection::Object(added));
    let valid = gi_studio::scene::ValidScene::new(scene.clone()).expect("a valid scene");
    let world = World::new(&valid);
    let (width, height) = (scene.settings.width, scene.settings.height);
    let ray = CameraModel::new(&scene.camera, width, height).pixel_ray(width as f32 / 2.0, height as f32 / 2.0);
    let seen = world.intersect(&ray, f32::INFINITY).map(|hit| hit.object as usize);
    assert_eq!(seen, Some(added), "the new sphere is not where the camera looks");
}

/// A material turned into a metal in the inspector, and the metal chosen:
/// each choice an edit that restarts the panes, each undone in one step;
/// the roughness slider moves both axes of an isotropic metal.
#[test]
fn a_material_becomes_a_metal_in_the_inspector() {
    use gi_studio::scene::{MaterialModel, Metal};
    let model_of = |app: &StudioApp| app.scene().materials.iter().find(|m| m.name == "glass").map(|m| m.model.clone());
    let mut harness = studio(1);
    step_until(&mut harness, |app| app.panes().list()[0].state().passes() >= 1);
    let original = harness.state().scene().clone();
    harness.get_by_label("glass (Glass)").click();
    harness.run_steps(2);
    harness.get_by_label("Model").click();
    harness.run_steps(2);
    harness.get_by_label("Metal").click();
    harness.run_steps(2);
    let gold = MaterialModel::Conductor { metal: Metal::Gold, alpha_u: 0.1, alpha_v: 0.1 };
    assert_eq!(model_of(harness.state()), Some(gold.clone()));
    let generation = harness.state().panes().generations()[0];
    harness.get_by_label("Made of").click();
    harness.run_steps(2);
    harness.get_by_label("Copper").click();
    harness.run_steps(3);
    let copper = MaterialModel::Conductor { metal: Metal::Copper, alpha_u: 0.1, alpha_v: 0.1 };
    assert_eq!(model_of(harness.state()), Some(copper.clone()));
    assert!(harness.state().panes().generations()[0] > generation, "choosing the metal must restart the render");
    // A click on the slider's middle makes the surface rougher, on both axes
    harness.get_by_role_and_label(Role::Slider, "Roughness α").click();
    harness.run_steps(3);
    match model_of(harness.state()) {
        Some(MaterialModel::Conductor { metal: Metal::Copper, alpha_u, alpha_v }) => {
            assert!(alpha_u > 0.3 && alpha_u == alpha_v, "α {alpha_u}, {alpha_v}")
        }
        other => panic!("{other:?}"),
    }
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(model_of(harness.state()), Some(copper));
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(model_of(harness.state()), Some(gold));
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(*harness.state().scene(), original);
}

/// A drag of 80 points turns the Cornell box's camera by a few degrees
/// (the field of view per image height), not out through its walls.
#[test]
fn an_orbit_drag_turns_with_the_view() {
    let mut harness = studio(1);
    harness.run_steps(2);
    let rect = harness.state().panes().rects()[0];
    let start = rect.center();
    drag(&mut harness, start, egui::vec2(80.0, 0.0), 8);
    let camera = &harness.state().scene().camera;
    let turned = (camera.position - camera.look_at).angle_between(glam::Vec3::new(0.0, 0.0, 3.4)).to_degrees();
    let expected = 40.0 * 80.0 / rect.height();
    assert!((turned - expected).abs() < 0.5, "turned {turned}° for an 80-point drag, not {expected}°");
    assert!(camera.position.x.abs() < 1.0, "the camera left the box: {}", camera.position);
}

#[test]
fn clicking_a_sphere_in_the_viewport_selects_it() {
    let mut harness = studio(1);
    step_until(&mut harness, |app| app.panes().list()[0].state().passes() >= 1);
    let app = harness.state();
    let rect = app.panes().rects()[0];
    let camera = CameraModel::new(&app.scene().camera, 64, 48);
    let film = camera.project(glam::Vec3::new(0.45, 0.35, 0.2)).expect("in view");
    let target = rect.min + egui::vec2(film.x / 64.0 * rect.width(), film.y / 48.0 * rect.height());
    let glass = app.scene().objects.iter().position(|o| o.name == "glass ball").unwrap();
    harness.hover_at(target);
    harness.run_steps(1);
    harness.event(egui::Event::PointerButton {
        pos: target,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: Default::default(),
    });
    harness.run_steps(1);
    harness.event(egui::Event::PointerButton {
        pos: target,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: Default::default(),
    });
    harness.run_steps(2);
    assert_eq!(harness.state().selection(), Selection::Object(glass));
}

#[test]
fn every_menu_opens_and_draws() {
    let mut harness = studio(1);
    harness.run_steps(2);
    for (menu, entry) in [
        ("File", "Open…"),
        ("Edit", "Undo"),
        ("View", "Plots"),
        ("Help", "Drop a .ron file on the window to open it, an .obj or .ply to import it."),
    ] {
        harness.get_by_label(menu).click();
        harness.run_steps(2);
        harness.get_by_label_contains(entry);
        if menu == "Help" {
            // About names every algorithm there is, Whitted to VCM
            let all: Vec<&str> = Algorithm::ALL.iter().map(|a| a.label()).collect();
            harness.get_by_label_contains(&all.join(" · "));
        }
        harness.key_press(egui::Key::Escape);
        harness.run_steps(2);
    }
}

#[test]
fn rendering_pauses_while_minimised_and_resumes_after() {
    let mut harness = studio(1);
    harness.state_mut().panes_mut().list_mut()[0].settings_mut().samples_per_pixel = None;
    harness.state_mut().restart_all();
    step_until(&mut harness, |app| app.panes().list()[0].state().passes() >= 1);
    let minimise = |harness: &mut Harness<'static, StudioApp>, minimised: bool| {
        harness.input_mut().viewports.entry(egui::ViewportId::ROOT).or_default().minimized = Some(minimised);
        harness.run_steps(2);
    };
    minimise(&mut harness, true);
    assert!(harness.state().is_paused());
    // At most the pass whose tiles were done when the pause came lands
    // after it (its event may still be on its way); no other (an unlimited
    // render would add several a frame at 64×48)
    let passes = harness.state().panes().list()[0].state().passes();
    for _ in 0..50 {
        harness.step();
        std::thread::sleep(std::time::Duration::from_millis(4));
    }
    let after = harness.state().panes().list()[0].state().passes();
    assert!(after <= passes + 1, "{} passes arrived while paused", after - passes);
    let passes = after;
    let generation = harness.state().panes().generations()[0];
    minimise(&mut harness, false);
    assert!(!harness.state().is_paused());
    assert!(harness.state().panes().generations()[0] > generation, "restored: the panes render again");
    step_until(&mut harness, |app| app.panes().list()[0].state().passes() > passes);
}

/// eframe storage in memory, as a second start would read it.
#[derive(Default)]
struct MemoryStorage(std::collections::HashMap<String, String>);

impl eframe::Storage for MemoryStorage {
    fn get_string(&self, key: &str) -> Option<String> {
        self.0.get(key).cloned()
    }
    fn set_string(&mut self, key: &str, value: String) {
        self.0.insert(key.to_owned(), value);
    }
    fn remove_string(&mut self, key: &str) {
        self.0.remove(key);
    }
    fn flush(&mut self) {}
}

/// What the window does: the studio keeps its state in a file and writes
/// it as it runs; a crash (the studio never closed: `kill -9`) finds the
/// layout and the unsaved edit there at the next start, offered back.
#[test]
fn layout_is_restored_and_an_unsaved_scene_is_offered_back() {
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("gistudio").join("app.ron");
    let interval = std::time::Duration::from_millis(50);
    let edited = {
        let args = StudioArgs { panes: Some(2), ..test_args() };
        let (file, notice) = StateFile::open(path.clone());
        assert!(notice.is_none());
        let mut app = StudioApp::new(&egui::Context::default(), Some(&file), &args);
        app.keep_state_in(file, interval);
        let mut harness =
            Harness::builder().with_size([1400.0, 900.0]).build_ui_state(|ui, app: &mut StudioApp| app.show(ui), app);
        harness.state_mut().edit_scene(|s| s.camera.fov_y_degrees = 55.0);
        let edited = harness.state().scene().clone();
        // Frames go on past the interval: the running studio writes the file
        step_frames_until(&mut harness, 500, |_| {
            StateFile::open(path.clone()).0.get_string("autosave_scene").is_some_and(|t| !t.is_empty())
        });
        // A crash: nothing the studio does at exit happens
        std::mem::forget(harness);
        edited
    };
    // Next start: two panes again, and the edit offered back
    let (file, notice) = StateFile::open(path.clone());
    assert!(notice.is_none());
    let app = StudioApp::new(&egui::Context::default(), Some(&file), &test_args());
    assert_eq!(app.panes().count(), 2);
    assert!(app.offers_autosave());
    let mut harness =
        Harness::builder().with_size([1400.0, 900.0]).build_ui_state(|ui, app: &mut StudioApp| app.show(ui), app);
    harness.run_steps(2);
    assert_ne!(*harness.state().scene(), edited);
    harness.get_by_label("Its edits: the camera.");
    harness.get_by_label("Restore").click();
    harness.run_steps(2);
    assert_eq!(*harness.state().scene(), edited);
    assert!(!harness.state().offers_autosave());
}

fn autosaved_storage(edited: &gi_studio::scene::Scene) -> MemoryStorage {
    let mut storage = MemoryStorage::default();
    storage.set_string("autosave_scene", gi_studio::scene::to_ron(edited).unwrap());
    storage
}

fn edited_cornell() -> gi_studio::scene::Scene {
    let mut scene = gi_studio::scene::presets::default_scene();
    scene.camera.fov_y_degrees = 61.0;
    scene
}

/// After a crash the autosave is offered back; until the user answers, the
/// studio's own saves must keep it (a second crash must not lose it), and
/// only a Discard clears it.
#[test]
fn an_unanswered_autosave_offer_keeps_the_autosave() {
    let edited = edited_cornell();
    let mut storage = autosaved_storage(&edited);
    let autosave = storage.get_string("autosave_scene");
    let mut app = StudioApp::new(&egui::Context::default(), Some(&storage), &test_args());
    assert!(app.offers_autosave());
    eframe::App::save(&mut app, &mut storage);
    assert_eq!(storage.get_string("autosave_scene"), autosave, "the unanswered offer's autosave was replaced");
    let mut harness =
        Harness::builder().with_size([1400.0, 900.0]).build_ui_state(|ui, app: &mut StudioApp| app.show(ui), app);
    harness.run_steps(2);
    harness.get_by_label("Discard").click();
    harness.run_steps(2);
    eframe::App::save(harness.state_mut(), &mut storage);
    assert_eq!(storage.get_string("autosave_scene").as_deref(), Some(""));
}

/// A `--screenshot` run (CI's, the README's) saves nothing: not the layout,
/// not the autosave, whatever it renders or shows.
#[test]
fn a_screenshot_run_never_touches_the_saved_state() {
    let edited = edited_cornell();
    let mut storage = autosaved_storage(&edited);
    storage.set_string("studio", "(panes: [], show_plots: false)".into());
    let before = storage.0.clone();
    let args = StudioArgs { screenshot: Some(PathBuf::from("shot.png")), panes: Some(4), ..test_args() };
    let mut app = StudioApp::new(&egui::Context::default(), Some(&storage), &args);
    assert!(app.offers_autosave(), "the offer shows as at any start, and stays unanswered");
    app.edit_scene(|s| s.camera.fov_y_degrees = 20.0);
    eframe::App::save(&mut app, &mut storage);
    assert_eq!(storage.0, before);
}

/// Saved settings no render can use (a pane of 100000², k = 2³²−1, tiles
/// of 0, a NaN exposure) fall back to defaults with a notice; the studio
/// starts and renders. A field an earlier version saved (100000 reference
/// threads) is passed over.
#[test]
fn unusable_saved_settings_fall_back_to_defaults_with_a_notice() {
    let mut storage = MemoryStorage::default();
    let broken = gi_studio::render::RenderSettings {
        width: 100_000,
        height: 100_000,
        tile_size: 0,
        method: gi_studio::render::Method::Photon(gi_studio::render::PhotonSettings {
            k_nearest: u32::MAX,
            ..Default::default()
        }),
        ..Default::default()
    };
    let fine =
        gi_studio::render::RenderSettings { width: 64, height: 48, samples_per_pixel: Some(1), ..Default::default() };
    let saved = gi_studio::app::Persisted {
        panes: vec![broken, fine.clone()],
        exposures: vec![f32::NAN, 1.0],
        show_plots: false,
        recent: Vec::new(),
    };
    let text = ron::to_string(&saved).unwrap();
    let earlier = format!("{}, reference_threads: 100000)", text.trim_end_matches(')'));
    storage.set_string("studio", earlier);
    let mut app = StudioApp::new(&egui::Context::default(), Some(&storage), &test_args());
    assert_eq!(app.panes().count(), 2);
    let first = app.panes().list()[0].settings();
    assert!(first.problems().is_empty(), "{:?}", first.problems());
    assert!(first.width <= 4096 && first.tile_size == 32);
    assert_eq!(*app.panes().list()[1].settings(), fine);
    assert_eq!((app.panes().list()[0].exposure(), app.panes().list()[1].exposure()), (0.0, 1.0));
    assert!(
        ["pane 1's saved size", "exposure"].iter().all(|s| app.messages().status.contains(s)),
        "{}",
        app.messages().status
    );
    for pane in app.panes_mut().list_mut() {
        pane.settings_mut().width = 32;
        pane.settings_mut().height = 24;
        pane.settings_mut().samples_per_pixel = Some(1);
    }
    app.restart_all();
    let mut harness =
        Harness::builder().with_size([1400.0, 900.0]).build_ui_state(|ui, app: &mut StudioApp| app.show(ui), app);
    step_until(&mut harness, |app| app.panes().list().iter().all(|p| p.state().finished));
}

/// Step until `done` holds, for work that takes seconds (a reference).
fn step_long_until(harness: &mut Harness<'static, StudioApp>, done: impl Fn(&StudioApp) -> bool) {
    step_frames_until(harness, 60_000, done);
}

/// An edited scene has no reference: one is rendered in the background
/// while the pane runs, and the pane's error becomes a figure measured
/// against it; the finished reference is kept, so undoing the edit finds
/// the preset's built-in reference and redoing it finds the kept one,
/// neither rendered again.
#[test]
fn an_edited_scene_is_measured_against_a_reference_made_in_the_background() {
    use gi_studio::app::{PaneError, Source};
    let cache = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let args = StudioArgs { panes: Some(1), reference_cache: Some(cache.path().to_owned()), ..Default::default() };
    let mut app = StudioApp::new(&egui::Context::default(), None, &args);
    *app.panes_mut().list_mut()[0].settings_mut() = gi_studio::render::RenderSettings {
        width: 64,
        height: 48,
        samples_per_pixel: None,
        ..gi_studio::render::RenderSettings::for_algorithm(gi_studio::render::Algorithm::Path)
    };
    let small = |s: &mut gi_studio::scene::Scene| (s.settings.width, s.settings.height) = (64, 48);
    app.edit_scene(small);
    let mut harness =
        Harness::builder().with_size([1400.0, 900.0]).build_ui_state(|ui, app: &mut StudioApp| app.show(ui), app);
    step_long_until(&mut harness, |app| matches!(app.references().source(), Some(Source::Rendering(_))));
    // The box's glass ball: BDPT finds its caustic
    harness.get_by_label_contains("bidirectional path tracing");
    step_long_until(
        &mut harness,
        |app| matches!(app.panes().list()[0].state().latest_error(), Some(PaneError::Measured(e)) if e.rel_mse.is_finite()),
    );
    // The label shows the measured figure, ± its standard error. A later
    // pass may fall back to the pane's own noise for a while (while the
    // reference's noise is more than three times the pane's error), so the
    // frames are looked at until one shows it: at the latest once the
    // reference is done, the figure stays measured
    let shown = (0..60_000).any(|_| {
        harness.step();
        std::thread::sleep(std::time::Duration::from_millis(2));
        harness.query_by_label_contains(" ±").is_some()
    });
    assert!(shown, "the pane never showed its error measured against the reference");
    let finished = |app: &StudioApp| matches!(app.references().source(), Some(Source::Rendering(p)) if !p.running && p.passes == p.target);
    step_long_until(&mut harness, finished);
    let kept = |dir: &std::path::Path| {
        std::fs::read_dir(dir).map_or(0, |entries| {
            entries.filter(|e| e.as_ref().is_ok_and(|e| e.path().extension().is_some_and(|x| x == "exr"))).count()
        })
    };
    step_long_until(&mut harness, |_| kept(cache.path()) == 1);
    // Undone: the preset as shipped, its built-in reference
    harness.state_mut().edit_scene(|s| (s.settings.width, s.settings.height) = (640, 480));
    step_long_until(&mut harness, |app| app.references().source() == Some(&Source::BuiltIn));
    harness.run_steps(2);
    harness.get_by_label_contains("built in");
    // Redone: the kept one, from the cache, saying how converged it is
    harness.state_mut().edit_scene(small);
    step_long_until(&mut harness, |app| app.references().source() == Some(&Source::Cache));
    assert_eq!(kept(cache.path()), 1, "nothing rendered again");
    harness.run_steps(2);
    harness.get_by_label_contains("from the cache (bdpt, 4096 of 4096 spp, its own relMSE");
    // …and can be rendered again on the user's word
    harness.get_by_label("Render again").click();
    harness.run_steps(2);
    assert!(matches!(harness.state().references().source(), Some(Source::Rendering(p)) if p.running));
}

/// A BDPT pane's "Strategies" button opens the strategy view without
/// restarting the pane; the view fills with every strategy's image as
/// passes arrive, each told with its share of the pane's light; closing it
/// renders without them again.
#[test]
fn the_strategy_view_shows_each_strategy_with_its_share() {
    let mut harness = studio(1);
    let pane = &mut harness.state_mut().panes_mut().list_mut()[0];
    pane.settings_mut().method = gi_studio::render::Method::of(gi_studio::render::Algorithm::Bdpt);
    pane.settings_mut().samples_per_pixel = Some(4096);
    harness.state_mut().restart_all();
    step_until(&mut harness, |app| app.panes().list()[0].state().passes() >= 1);
    let generation = harness.state().panes().generations()[0];
    harness.get_by_label("Strategies").click();
    harness.run_steps(1);
    assert_eq!(harness.state().panes().generations()[0], generation, "opening the view restarted the pane");
    step_until(&mut harness, |app| app.panes().list()[0].state().strategies.as_ref().is_some_and(|s| s.passes >= 2));
    harness.run_steps(2);
    let cell = harness.get_by_label_contains("(s, t) = (1, 2): ");
    let label = egui_kittest::kittest::NodeT::accesskit_node(&cell).label().unwrap_or_default();
    assert!(label.ends_with("% of the pane's light"), "{label}");
    let share: f64 = label.split(": ").nth(1).and_then(|t| t.split('%').next()).and_then(|p| p.parse().ok()).unwrap();
    assert!(share > 0.0 && share < 100.0, "{label}");
    assert!(harness.query_by_label_contains("merged at camera vertex").is_none(), "BDPT does not merge");
    harness.get_by_label("Strategies").click();
    harness.run_steps(2);
    assert!(harness.query_by_label_contains("(s, t) = (1, 2): ").is_none(), "the view closed");
}

/// An SPPM pane's last pass is split into its stages under the photon
/// plots: each stage named with its milliseconds.
#[test]
fn the_photon_plots_split_an_sppm_pass_into_its_stages() {
    let mut harness = studio(1);
    let pane = &mut harness.state_mut().panes_mut().list_mut()[0];
    pane.settings_mut().method = gi_studio::render::Method::of(gi_studio::render::Algorithm::Sppm);
    pane.settings_mut().set_photons(5_000);
    harness.state_mut().restart_all();
    step_until(&mut harness, |app| {
        app.panes().list()[0].state().stats.as_ref().is_some_and(|s| s.photon.photons_traced > 0)
    });
    harness.run_steps(2);
    let node = harness.get_by_label_contains("1: SPPM last pass: ");
    let node = egui_kittest::kittest::NodeT::accesskit_node(&node);
    let label = node.label().or_else(|| node.value()).unwrap_or_default();
    for stage in ["eye pass", "photon tracing", "photon grid", "gather"] {
        let after = label.split(&format!("{stage} ")).nth(1).unwrap_or_else(|| panic!("no {stage} in {label}"));
        let ms: Option<f64> = after.split_whitespace().next().and_then(|w| w.parse().ok());
        assert!(ms.is_some_and(f64::is_finite) && after.contains(" ms"), "{label}");
    }
}

/// A VCM pane's settings say where it merges: the checkbox flips the
/// pane's setting and renders it again; a BDPT pane, which never merges,
/// offers no such box.
#[test]
fn a_vcm_pane_chooses_where_it_merges() {
    use gi_studio::render::{Algorithm, Method};
    let mut harness = studio(1);
    let pane = &mut harness.state_mut().panes_mut().list_mut()[0];
    pane.settings_mut().method = Method::of(Algorithm::Vcm);
    harness.state_mut().restart_all();
    harness.run_steps(2);
    let caustics = |harness: &Harness<'static, StudioApp>| match &harness.state().panes().list()[0].settings().method {
        Method::Vcm(m) => m.caustic_merges,
        other => panic!("not VCM: {other:?}"),
    };
    let (before, generation) = (caustics(&harness), harness.state().panes().list()[0].state().generation);
    harness.get_by_label("Settings").click();
    harness.run_steps(2);
    harness.get_by_label("merge caustic paths only").click();
    harness.run_steps(2);
    assert_eq!(caustics(&harness), !before, "the box did not flip the setting");
    assert!(harness.state().panes().list()[0].state().generation > generation, "not rendered again");
    let pane = &mut harness.state_mut().panes_mut().list_mut()[0];
    pane.settings_mut().method = Method::of(Algorithm::Bdpt);
    harness.run_steps(2);
    // The menu open on BDPT's knobs (its heuristic)
    if harness.query_by_label("balance").is_none() {
        harness.get_by_label("Settings").click();
        harness.run_steps(2);
    }
    harness.get_by_label("balance");
    assert!(harness.query_by_label("merge caustic paths only").is_none(), "BDPT offers where to merge");
}

/// Ctrl and the wheel over a pane zoom every pane's image about the
/// pointer and leave the camera alone (no edit, no restart); F shows the
/// whole images again.
#[test]
fn ctrl_and_the_wheel_zoom_the_images_not_the_camera() {
    let mut harness = studio(2);
    step_until(&mut harness, |app| app.panes().list().iter().all(|p| p.state().passes() >= 1));
    let original = harness.state().scene().clone();
    let generations = harness.state().panes().generations();
    let rect = harness.state().panes().rects()[0];
    harness.hover_at(rect.center() + egui::vec2(rect.width() * 0.25, 0.0));
    harness.run_steps(1);
    for _ in 0..3 {
        harness.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Line,
            delta: egui::vec2(0.0, 1.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Wheel,
            modifiers: egui::Modifiers::COMMAND,
        });
        harness.run_steps(1);
    }
    harness.run_steps(8);
    let view = *harness.state().panes().view();
    assert!(view.zoom() > 1.5, "Ctrl and the wheel did not zoom: {view:?}");
    // About the pointer, right of the middle: the view moved right
    assert!(view.visible().center().x > 0.5, "{view:?}");
    assert_eq!(*harness.state().scene(), original, "zooming the images moved the camera");
    assert_eq!(harness.state().panes().generations(), generations, "zooming the images restarted a pane");
    harness.key_press(egui::Key::F);
    harness.run_steps(2);
    assert!(harness.state().panes().view().fits(), "{:?}", harness.state().panes().view());
}

/// The pointer over one pane reads out the pixel under it in every pane:
/// each pane's own value there, bit for bit what its image holds.
#[test]
fn every_pane_reads_out_the_pixel_under_the_pointer() {
    let mut harness = studio(2);
    step_until(&mut harness, |app| app.panes().list().iter().all(|p| p.state().finished));
    let rect = harness.state().panes().rects()[1];
    // 64 × 48 images: 0.26 across and 0.51 down is pixel (16, 24)
    harness.hover_at(rect.min + egui::vec2(rect.width() * 0.26, rect.height() * 0.51));
    harness.run_steps(3);
    let readouts = harness.query_all_by_label_contains("pixel (16, 24)").count();
    assert_eq!(readouts, 2, "one read-out per pane");
    for pane in harness.state().panes().list() {
        let [r, g, b] = pane.state().image.get(16, 24);
        let value = format!("RGB {r:.4} {g:.4} {b:.4}");
        assert!(harness.query_by_label_contains(&value).is_some(), "no read-out shows {value}");
    }
    // Away from the images, no read-out
    harness.hover_at(egui::pos2(2.0, 2.0));
    harness.run_steps(3);
    assert_eq!(harness.query_all_by_label_contains("pixel (").count(), 0);
}

/// A wipe shows pane 2's image right of a divider over pane 1; dragging
/// the divider moves it by the dragged share of the pane and leaves the
/// camera alone; choosing Off ends it.
#[test]
fn a_wipe_divider_follows_the_drag_and_not_the_camera() {
    let mut harness = studio(2);
    step_until(&mut harness, |app| app.panes().list().iter().all(|p| p.state().passes() >= 1));
    let original = harness.state().scene().clone();
    harness.get_all_by_label("Wipe").next().expect("pane 1's wipe menu").click();
    harness.run_steps(2);
    harness.get_by_label("with pane 2").click();
    harness.run_steps(3);
    let wipe = harness.state().panes().wipe(0).expect("the wipe is on");
    assert_eq!((wipe.other, wipe.divider), (Against::Pane(1), 0.5));
    assert!(harness.query_by_label("wipe pane 1 | pane 2").is_some(), "no divider drawn");
    let rect = harness.state().panes().rects()[0];
    let start = rect.center();
    let dx = -rect.width() / 4.0;
    drag(&mut harness, start, egui::vec2(dx, 0.0), 5);
    let divider = harness.state().panes().wipe(0).expect("still on").divider;
    assert!((divider - 0.25).abs() < 0.01, "the divider stands at {divider}, not 0.25");
    assert_eq!(*harness.state().scene(), original, "dragging the divider moved the camera");
    // Against the reference (the built-in one, there from the start)
    harness.get_all_by_label("Wipe").next().expect("pane 1's wipe menu").click();
    harness.run_steps(2);
    harness.get_by_label("with the reference").click();
    harness.run_steps(3);
    assert_eq!(harness.state().panes().wipe(0).map(|w| w.other), Some(Against::Reference));
    assert!(harness.query_by_label("wipe pane 1 | reference").is_some(), "no divider against the reference");
    harness.get_all_by_label("Wipe").next().expect("pane 1's wipe menu").click();
    harness.run_steps(2);
    harness.get_by_label("Off").click();
    harness.run_steps(2);
    assert_eq!(harness.state().panes().wipe(0), None);
}

/// Selecting an object outlines it in every pane: the outline surrounds
/// where the camera sees its centre; selecting the camera removes it.
#[test]
fn the_selected_object_is_outlined_in_every_pane() {
    let mut harness = studio(2);
    step_until(&mut harness, |app| app.panes().list().iter().all(|p| p.state().passes() >= 1));
    assert!(harness.state().panes().outline(0).is_empty(), "an outline with nothing selected");
    harness.get_by_label("glass ball (sphere)").click();
    harness.run_steps(3);
    let centre = match harness.state().scene().objects.iter().find(|o| o.name == "glass ball").map(|o| &o.shape) {
        Some(Shape::Sphere { center, .. }) => *center,
        _ => panic!("no glass ball"),
    };
    let film = CameraModel::new(&harness.state().scene().camera, 64, 48).project(centre).expect("in view");
    let seen = egui::vec2(film.x / 64.0, film.y / 48.0);
    for index in 0..2 {
        let outline = harness.state().panes().outline(index);
        assert!(outline.len() > 8, "pane {index}: {} edges", outline.len());
        let points = || outline.iter().flatten();
        let (min_x, max_x) = points().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p.x), hi.max(p.x)));
        let (min_y, max_y) = points().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
        assert!((min_x..max_x).contains(&seen.x) && (min_y..max_y).contains(&seen.y), "pane {index}: {seen:?} outside");
        // Not the whole image: the ball covers a part of it
        assert!(max_x - min_x < 0.6 && max_y - min_y < 0.8, "pane {index}: {min_x}..{max_x} × {min_y}..{max_y}");
    }
    harness.get_by_label("Camera").click();
    harness.run_steps(3);
    assert!(harness.state().panes().outline(0).is_empty(), "the outline stayed after the selection went");
}

/// The difference view compares the chosen pane with the chosen image:
/// the reference first, then another pane, in either metric, with its scale.
#[test]
fn the_difference_view_compares_the_chosen_images() {
    let mut harness = studio(2);
    step_until(&mut harness, |app| app.panes().list().iter().all(|p| p.state().passes() >= 1));
    harness.get_by_label("View").click();
    harness.run_steps(2);
    harness.get_by_label("Difference view").click();
    harness.key_press(egui::Key::Escape);
    harness.run_steps(3);
    // The built-in reference is larger than these small panes
    harness.get_by_label("no reference at this pane's size or a whole fraction of it");
    harness.get_by_label("as").click();
    harness.run_steps(2);
    harness.get_by_label("pane 2's image").click();
    harness.run_steps(3);
    harness.get_by_label("pane 1 against pane 2");
    harness.get_by_label_contains("(relative error, 99th percentile and above)");
    harness.get_by_label("signed").click();
    harness.run_steps(3);
    harness.get_by_label_contains("(luminance, 99th percentile of |a − b|)");
}

/// A point light shows as a handle in every pane: a click selects it, a
/// drag moves it across the view at its depth, one undo step.
#[test]
fn a_light_handle_selects_and_moves_its_light() {
    let mut harness = studio(2);
    harness.run_steps(2);
    harness.state_mut().edit_scene(|scene| {
        scene.lights.push(gi_studio::scene::Light {
            name: "bulb".into(),
            kind: gi_studio::scene::LightKind::Point { position: glam::Vec3::new(0.2, 1.4, 0.0) },
            color: glam::Vec3::ONE,
            intensity: 1.0,
            attenuation: gi_studio::scene::Attenuation::default(),
            enabled: true,
        })
    });
    harness.run_steps(3);
    let index = harness.state().scene().lights.len() - 1;
    assert_eq!(harness.query_all_by_label("light bulb").count(), 2, "one handle a pane");
    harness.get_all_by_label("light bulb").next().expect("a handle").click();
    harness.run_steps(2);
    assert_eq!(harness.state().selection(), Selection::Light(index));
    let before = harness.state().scene().clone();
    let at = harness.get_all_by_label("light bulb").next().expect("a handle").rect().center();
    drag(&mut harness, at, egui::vec2(20.0, 0.0), 4);
    let position = |scene: &gi_studio::scene::Scene| match scene.lights[index].kind {
        gi_studio::scene::LightKind::Point { position } => position,
        _ => panic!("not a point light"),
    };
    let moved = position(harness.state().scene()) - position(&before);
    // The camera looks down −z with y up: right is +x; the view does not move
    assert!(moved.x > 0.01 && moved.y.abs() < 1e-4 && moved.z.abs() < 1e-4, "moved {moved}");
    assert_eq!(harness.state().scene().camera, before.camera, "dragging the light moved the camera");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(*harness.state().scene(), before, "one undo takes back the drag");
}

/// A file dropped on the window, as the windowing layer hands it over.
#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &std::path::Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

/// A cube as a Wavefront OBJ (six quads).
fn cube_obj() -> String {
    let corners = ["0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"];
    let faces = ["1 4 3 2", "5 6 7 8", "1 2 6 5", "3 4 8 7", "2 3 7 6", "1 5 8 4"];
    corners.iter().map(|c| format!("v {c}\n")).chain(faces.iter().map(|f| format!("f {f}\n"))).collect()
}

/// A dropped OBJ becomes an object in view, selected, that the panes
/// render (the image changes) and one undo removes; a broken one is
/// refused with its reason and changes nothing. File ▸ Import mesh… reads
/// one through the dialog.
#[test]
fn a_dropped_or_imported_mesh_joins_the_scene_in_view() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("gi-ui-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (cube, broken) = (dir.join("cube.obj"), dir.join("broken.ply"));
    std::fs::write(&cube, cube_obj()).unwrap();
    std::fs::write(&broken, "ply\nformat ascii 1.0\nelement vertex 900000000\nend_header\n").unwrap();
    let mut harness = studio(1);
    step_until(&mut harness, |app| app.panes().list()[0].state().finished);
    let (before, image) =
        (harness.state().scene().clone(), harness.state().panes().list()[0].state().image.pixels.clone());
    let drop = |harness: &mut Harness<'static, StudioApp>, path: &std::path::Path| {
        harness.input_mut().dropped_files.push(std::sync::Arc::new(Dropped(path.to_owned())));
        harness.run_steps(2);
    };
    // Read on a thread of its own: the frames go on meanwhile
    drop(&mut harness, &broken);
    step_until(&mut harness, |app| app.messages().error.is_some());
    assert_eq!(*harness.state().scene(), before);
    let error = harness.state().messages().error.clone().expect("an error is shown");
    assert!(error.contains("broken.ply") && error.contains("more than the file holds"), "{error}");

    drop(&mut harness, &cube);
    step_until(&mut harness, |app| app.scene().objects.len() > before.objects.len());
    let objects = &harness.state().scene().objects;
    let added = objects.last().expect("an object");
    assert_eq!((objects.len(), added.name.as_str()), (before.objects.len() + 1, "cube"));
    assert_eq!(harness.state().selection(), Selection::Object(objects.len() - 1));
    let Shape::Mesh { translate, .. } = added.shape else { panic!("not a mesh: {:?}", added.shape) };
    let camera = CameraModel::new(&before.camera, 64, 48);
    let at = camera.project(translate).expect("the cube in front of the camera");
    let (x, y) = (at.x, at.y);
    assert!((0.0..64.0).contains(&x) && (0.0..48.0).contains(&y), "the cube at ({x}, {y}), out of view");
    step_until(&mut harness, |app| {
        app.panes().list()[0].state().finished && app.scene().objects.len() > before.objects.len()
    });
    assert_ne!(harness.state().panes().list()[0].state().image.pixels, image, "the cube is not rendered");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().scene().objects, before.objects);

    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label("Import mesh…").click();
    harness.run_steps(4);
    harness.get_by_label("Import mesh (OBJ, PLY)");
    answer_file_dialog(&mut harness, &cube, "Import");
    step_until(&mut harness, |app| matches!(app.scene().objects.last().map(|o| &o.shape), Some(Shape::Mesh { .. })));
}

/// A scene of many objects lists only the rows in view (a list of 100,000
/// took seconds a frame to lay out), and scrolls to the rest.
#[test]
fn a_long_object_list_lays_out_only_the_rows_in_view() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("gi-ui-many-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut scene = gi_studio::scene::presets::preset("cornell").unwrap().unwrap().into_scene();
    for k in 0..2000 {
        let center = glam::Vec3::new(-0.9 + 0.0009 * k as f32, 0.02, -0.9);
        let shape = Shape::Sphere { center, radius: 0.0004 };
        scene.objects.push(gi_studio::scene::Object { name: format!("speck {k}"), shape, material: "white".into() });
    }
    let path = dir.join("many.ron");
    std::fs::write(&path, gi_studio::scene::to_ron(&scene).unwrap()).unwrap();
    let mut harness = studio(1);
    harness.state_mut().open_path(&path);
    harness.run_steps(3);
    assert_eq!(harness.state().scene().objects.len(), scene.objects.len());
    harness.get_by_label("speck 0 (sphere)");
    assert!(harness.query_by_label("speck 1999 (sphere)").is_none(), "every row laid out");
}
