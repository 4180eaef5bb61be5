//! The progressive engine: determinism, restarts, and every preset rendering
//! finite images with both algorithms.

mod common;

use common::valid;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

use gi_studio::render::film::Film;
use gi_studio::render::integrators::photon_map::trace::{trace_photons_until, MapKind, PhotonBatch, CHUNK};
use gi_studio::render::integrators::{Integrator, PassObserver, Stage};
use gi_studio::render::world::camera::{CameraModel, TileRect};
use gi_studio::render::world::lane_world::LaneWorld;
use gi_studio::render::world::World;

use gi_studio::render::{
    render_blocking, render_blocking_on, Algorithm, RenderEvent, RenderJob, RenderSession, RenderSettings, Workers,
};
use gi_studio::scene::presets;

fn job(name: &str, algorithm: Algorithm, width: u32, height: u32, spp: u32) -> RenderJob {
    let scene = presets::preset(name).unwrap().unwrap();
    let settings = RenderSettings {
        width,
        height,
        samples_per_pixel: Some(spp),
        seed: 11,
        ..RenderSettings::for_algorithm(algorithm)
    };
    RenderJob::new(Arc::new(valid(scene)), settings)
}

#[test]
fn same_seed_gives_bit_identical_images_with_one_or_two_threads() {
    let (one_thread, two_threads) = (Workers::new(1).unwrap(), Workers::new(2).unwrap());
    for algorithm in [Algorithm::Path, Algorithm::Whitted, Algorithm::Photon, Algorithm::Sppm] {
        let one = render_blocking_on(&one_thread, &job("cornell", algorithm, 48, 36, 3)).unwrap().0;
        let two = render_blocking_on(&two_threads, &job("cornell", algorithm, 48, 36, 3)).unwrap().0;
        assert_eq!(one, two, "{algorithm}");
        let mut other_seed = job("cornell", algorithm, 48, 36, 3);
        other_seed.settings.seed = 12;
        assert_ne!(render_blocking(&other_seed).unwrap().0, one, "{algorithm}: the seed must matter");
    }
}

#[test]
fn every_preset_renders_finite_with_both_algorithms() {
    for name in presets::names() {
        for algorithm in [Algorithm::Path, Algorithm::Whitted] {
            let (image, stats) = render_blocking(&job(name, algorithm, 40, 30, 2)).unwrap();
            assert_eq!(stats.non_finite, 0, "{name} {algorithm}");
            assert!(image.pixels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0), "{name} {algorithm}");
            assert!(image.mean().iter().sum::<f64>() > 0.0, "{name} {algorithm} rendered black");
            assert_eq!(stats.passes, 2);
            assert!(stats.rays >= stats.samples);
        }
    }
}

#[test]
fn restart_abandons_the_old_job_and_only_the_new_one_finishes() {
    let session = RenderSession::new(Workers::shared().unwrap(), None).unwrap();
    let mut slow = job("smallpt", Algorithm::Path, 256, 192, 10_000);
    slow.settings.samples_per_pixel = None;
    let old = session.start(slow);
    // Let the first job get going, then replace it
    let first = session.events().recv_timeout(Duration::from_secs(30)).unwrap();
    assert_eq!(first.generation(), old);
    let new = session.start(job("cornell", Algorithm::Whitted, 32, 24, 2));
    assert!(new > old);
    let mut finished = Vec::new();
    while let Ok(event) = session.events().recv_timeout(Duration::from_secs(60)) {
        if let RenderEvent::Finished { generation, .. } = event {
            finished.push(generation);
            break;
        }
    }
    assert_eq!(finished, vec![new]);
}

#[test]
fn preview_tiles_come_first_and_cover_the_image() {
    let mut job = job("thesis", Algorithm::Path, 64, 48, 1);
    job.settings.preview = true;
    let session = RenderSession::new(Workers::shared().unwrap(), None).unwrap();
    let generation = session.start(job);
    let mut preview_pixels = 0;
    let mut saw_final_tile = false;
    for event in session.events().iter() {
        match event {
            RenderEvent::Tile(tile) if tile.generation == generation => {
                if tile.preview {
                    assert!(!saw_final_tile, "previews come before the first pass");
                    preview_pixels += tile.pixels.len();
                } else {
                    saw_final_tile = true;
                }
            }
            RenderEvent::Finished { .. } => break,
            _ => {}
        }
    }
    assert_eq!(preview_pixels, 64 * 48);
    assert!(saw_final_tile);
}

/// Every tile after every pass when asked (path tracing and SPPM alike),
/// none otherwise, and the same image either way.
#[test]
fn tiles_stream_after_each_pass_only_when_asked() {
    for algorithm in [Algorithm::Path, Algorithm::Sppm] {
        let mut images = Vec::new();
        for stream_tiles in [true, false] {
            // 64 × 48 in tiles of 32: four tiles, three passes
            let job = RenderJob { stream_tiles, ..job("cornell", algorithm, 64, 48, 3) };
            let session = RenderSession::new(Workers::shared().unwrap(), None).unwrap();
            let generation = session.start(job);
            let mut tiles = 0;
            for event in session.events().iter() {
                match event {
                    RenderEvent::Tile(tile) if tile.generation == generation => tiles += 1,
                    RenderEvent::Finished { image, .. } => {
                        images.push(image);
                        break;
                    }
                    _ => {}
                }
            }
            assert_eq!(tiles, if stream_tiles { 4 * 3 } else { 0 }, "{algorithm}, streaming {stream_tiles}");
        }
        assert_eq!(images[0], images[1], "{algorithm}: streaming changed the image");
    }
}

/// A time budget and no sample target: the job ends by itself (the
/// budget is checked between passes), after at least one pass.
#[test]
fn a_time_budget_ends_the_render() {
    let mut job = job("cornell", Algorithm::Path, 32, 24, 1);
    job.settings.samples_per_pixel = None;
    job.settings.time_limit = Some(0.2);
    let session = RenderSession::new(Workers::shared().unwrap(), None).unwrap();
    let generation = session.start(job);
    let finished = loop {
        match session.events().recv_timeout(Duration::from_secs(120)).expect("the job ends") {
            RenderEvent::Finished { generation: g, stats, .. } if g == generation => break stats,
            _ => {}
        }
    };
    assert!(finished.passes >= 1);
}

/// A scene reaches the engine only checked (`ValidScene`); settings out of
/// their limits, which a driver could still send, fail instead of rendering.
#[test]
fn settings_out_of_their_limits_fail_instead_of_rendering() {
    let mut job = job("cornell", Algorithm::Path, 8, 8, 1);
    job.settings.tile_size = 0;
    let error = render_blocking(&job).unwrap_err();
    assert!(error.starts_with("tile_size: must be between 4 and 512"), "{error}");
}

/// Sessions sharing one pool take turns pass by pass: a render that never
/// ends (a background reference, a pane left running) does not hold back
/// another session's render on the same threads, nor its shutdown.
#[test]
fn a_render_that_never_ends_does_not_hold_back_another_on_the_same_workers() {
    let workers = Workers::new(1).unwrap();
    let endless = RenderSession::new(&workers, None).unwrap();
    let mut forever = job("cornell", Algorithm::Path, 48, 36, 1);
    forever.settings.samples_per_pixel = None;
    let endless_generation = endless.start(forever);
    // Wait until the endless render holds the only thread
    let started = endless.events().iter().find(|e| matches!(e, RenderEvent::PassFinished { .. }));
    assert!(started.is_some_and(|e| e.generation() == endless_generation));
    let short = RenderSession::new(&workers, None).unwrap();
    let generation = short.start(job("cornell", Algorithm::Path, 48, 36, 4));
    // A hang guard, not a timing test: the short render takes milliseconds;
    // held behind the endless one it would never finish
    let finished = loop {
        match short.events().recv_timeout(Duration::from_secs(120)) {
            Ok(RenderEvent::Finished { generation: g, stats, .. }) if g == generation => break Some(stats),
            Ok(_) => {}
            Err(_) => break None,
        }
    };
    assert_eq!(finished.map(|s| s.passes), Some(4), "the short render never finished");
    // Waited for, not polled: a pass's event may still be on its way
    // from the session's thread when the short render's end arrives
    let goes_on = loop {
        match endless.events().recv_timeout(Duration::from_secs(120)) {
            Ok(RenderEvent::PassFinished { .. }) => break true,
            Ok(_) => {}
            Err(_) => break false,
        }
    };
    assert!(goes_on, "the endless one goes on");
    drop(short);
    drop(endless);
}

/// Two panes on one pool: each pane's clock counts only its own stages, so
/// the two clocks add up to no more than the time both renders took
/// together. Sharing the threads at once, each clock would count the
/// other's work too, and they would add up to nearly twice that.
#[test]
fn each_session_counts_only_its_own_time_on_shared_workers() {
    let workers = Workers::new(2).unwrap();
    let sessions = [RenderSession::new(&workers, None).unwrap(), RenderSession::new(&workers, None).unwrap()];
    let start = std::time::Instant::now();
    let generations = sessions.each_ref().map(|session| session.start(job("cornell", Algorithm::Path, 96, 72, 24)));
    let times = [0, 1].map(|i| loop {
        // A hang guard, not a timing test
        match sessions[i].events().recv_timeout(Duration::from_secs(120)) {
            Ok(RenderEvent::Finished { generation, stats, .. }) if generation == generations[i] => {
                assert_eq!(stats.passes, 24);
                break stats.elapsed;
            }
            Ok(_) => {}
            Err(_) => panic!("render {i} never finished"),
        }
    });
    let whole = start.elapsed();
    assert!(times[0] + times[1] <= whole, "the panes' times {times:?} add up to more than the {whole:?} both took");
}

/// A driver that abandons its job at its `after`-th tile and counts the
/// tiles still finished after that: the work a cancel waits for.
struct Abandoning {
    /// Tiles shown before the pass is no longer wanted
    after: usize,
    /// Or questions asked (for passes that show their tiles only at the end)
    after_questions: usize,
    tiles: std::sync::atomic::AtomicUsize,
    late: std::sync::atomic::AtomicUsize,
    asked: std::sync::atomic::AtomicUsize,
}

impl Abandoning {
    fn new(after: usize) -> Self {
        Self { after, after_questions: usize::MAX, tiles: 0.into(), late: 0.into(), asked: 0.into() }
    }
}

impl PassObserver for Abandoning {
    fn is_current(&self) -> bool {
        let asked = self.asked.fetch_add(1, Ordering::SeqCst);
        self.tiles.load(Ordering::SeqCst) < self.after && asked < self.after_questions
    }
    fn wants_tiles(&self) -> bool {
        true
    }
    fn wants_variance(&self) -> bool {
        false
    }
    fn wants_noise(&self, _pass: u32) -> bool {
        false
    }
    fn tile(&self, _rect: TileRect, _pixels: Vec<[f32; 3]>, _variance: Option<Vec<[f32; 3]>>) {
        if self.tiles.fetch_add(1, Ordering::SeqCst) >= self.after {
            self.late.fetch_add(1, Ordering::SeqCst);
        }
    }
}

/// A restart answers within a bound of work, not of time: once a pass's
/// driver says it is no longer wanted, at most one more tile a worker is
/// finished (those already started), for every algorithm's pass; and
/// photon tracing asks before every chunk of photons, so a cancel during a
/// map of millions waits for one chunk a worker at most. The bidirectional
/// methods show their tiles only once the light paths' splats are in: they
/// ask before every chunk of light paths and every tile of camera paths,
/// and a pass abandoned there shows nothing.
#[test]
fn a_cancel_waits_for_at_most_one_tile_or_chunk_a_worker() {
    let workers = Workers::new(2).unwrap();
    for algorithm in Algorithm::ALL {
        let job = job("cornell", algorithm, 160, 120, 1);
        let mut settings = job.settings.clone();
        settings.tile_size = 8; // 300 tiles: a cancel at the 20th leaves most undone
        settings.set_photons(20_000);
        let camera = CameraModel::new(&job.scene.camera, settings.width, settings.height);
        let (world, visible) = World::for_view(&job.scene, &camera, settings.width, settings.height);
        let lanes = LaneWorld::new(&world);
        let stage = Stage { world: &world, camera: &camera, settings: &settings, lanes: lanes.as_ref() };
        let mut film = Film::new(settings.width, settings.height, settings.tile_size, false);
        let keep = Abandoning::new(usize::MAX);
        let mut integrator = Integrator::prepare(&stage, &film, visible, None, &keep).expect("prepared");
        let driver = if algorithm.is_bidirectional() {
            Abandoning { after_questions: 20, ..Abandoning::new(usize::MAX) }
        } else {
            Abandoning::new(20)
        };
        let report = workers.run(|| integrator.pass(&stage, &mut film, 0, &driver));
        assert!(report.is_none(), "{algorithm}: an abandoned pass reports nothing");
        if algorithm.is_bidirectional() {
            assert_eq!(driver.tiles.load(Ordering::SeqCst), 0, "{algorithm}: an abandoned pass shows no tile");
            continue;
        }
        let late = driver.late.load(Ordering::SeqCst);
        assert!(late <= 1, "{algorithm}: {late} tiles finished after the cancel, on 2 workers");
        assert!(driver.tiles.load(Ordering::SeqCst) < 40, "{algorithm}: the pass went on");
    }

    let scene = valid(presets::preset("cornell").unwrap().unwrap());
    let world = World::new(&scene);
    let count = 100 * CHUNK;
    let asked = std::sync::atomic::AtomicUsize::new(0);
    let mut photons = Vec::new();
    let lanes = LaneWorld::new(&world);
    let batch = PhotonBatch { kind: MapKind::Global, count, pass: 0, seed: 1, max_depth: 8 };
    let all = trace_photons_until(
        &world,
        lanes.as_ref(),
        batch,
        &|| {
            asked.fetch_add(1, Ordering::SeqCst);
            true
        },
        &mut photons,
    );
    assert!(all.is_some());
    assert_eq!(asked.load(Ordering::SeqCst), 100, "one question a chunk");
    // Told to stop at the fifth question: none but the chunks in flight go on
    let asked = std::sync::atomic::AtomicUsize::new(0);
    let traced = std::sync::atomic::AtomicUsize::new(0);
    let stopped = workers.run(|| {
        let keep_going = || {
            let go = asked.fetch_add(1, Ordering::SeqCst) < 5;
            traced.fetch_add(go as usize, Ordering::SeqCst);
            go
        };
        trace_photons_until(&world, lanes.as_ref(), batch, &keep_going, &mut photons)
    });
    assert!(stopped.is_none(), "an abandoned trace gives no map");
    assert_eq!(traced.load(Ordering::SeqCst), 5, "only the chunks told to go on were traced");
}

/// A session renders one job after another to its end (the detector
/// `tests/injected_bugs.rs` shows failing, not hanging, when a render
/// worker panics).
#[test]
fn renders_end_and_the_session_serves_the_next() {
    common::detectors::renders_end_and_sessions_go_on().expect("both renders finish");
}
